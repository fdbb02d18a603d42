// How channel values drive muscle strips, shared by the strip controllers
// (strip_network_controller.h, strip_open_loop_controller.h): strip s, driven
// by channel c_s with sign sigma_s = +1 or -1, contracts by
// u_s = max(sigma_s w_{c_s}, 0) (derivative 0 where sigma_s w_{c_s} <= 0).
#pragma once

#include <string>
#include <vector>

#include "diffpd/types.h"

namespace diffpd {

// Which channel drives a strip, and with which sign.
struct StripDrive {
  int channel = 0;
  int sign = 1;  // +1: u = max(w, 0); -1: u = max(-w, 0)
};

// Throws InvalidInputError "<owner>: ..." when there is not one drive per
// strip ("3 strip drives given, expected 8 (one per strip)"), a channel is
// outside [0, num_channels) ("drives[2].channel = 5 is out of range [0, 4)
// (<channels_are>)") or a sign is not +1 or -1.
void CheckStripDrives(const std::vector<StripDrive>& drives, int num_strips, int num_channels, const std::string& owner,
                      const std::string& channels_are);

// The contractions u (one per drive) of channel values w.
VectorXd StripContractions(const std::vector<StripDrive>& drives, const VectorXd& w);

// Adds (du/dw)^T g_u to *g_w (sized as w).
void AddStripContractionsVjp(const std::vector<StripDrive>& drives, const VectorXd& w, const VectorXd& g_u,
                             VectorXd* g_w);

}  // namespace diffpd
