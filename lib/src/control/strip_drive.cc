#include "diffpd/strip_drive.h"

#include <algorithm>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd {

void CheckStripDrives(const std::vector<StripDrive>& drives, int num_strips, int num_channels, const std::string& owner,
                      const std::string& channels_are) {
  std::ostringstream msg;
  msg << owner << ": ";
  if (static_cast<int>(drives.size()) != num_strips) {
    msg << drives.size() << " strip drives given, expected " << num_strips << " (one per strip)";
    throw InvalidInputError(msg.str());
  }
  for (size_t s = 0; s < drives.size(); ++s) {
    if (drives[s].channel < 0 || drives[s].channel >= num_channels) {
      msg << "drives[" << s << "].channel = " << drives[s].channel << " is out of range [0, " << num_channels << ") ("
          << channels_are << ")";
      throw InvalidInputError(msg.str());
    }
    if (drives[s].sign != 1 && drives[s].sign != -1) {
      msg << "drives[" << s << "].sign = " << drives[s].sign << " is invalid: must be +1 or -1";
      throw InvalidInputError(msg.str());
    }
  }
}

VectorXd StripContractions(const std::vector<StripDrive>& drives, const VectorXd& w) {
  VectorXd u(drives.size());
  for (size_t s = 0; s < drives.size(); ++s) u(s) = std::max(drives[s].sign * w(drives[s].channel), 0.0);
  return u;
}

void AddStripContractionsVjp(const std::vector<StripDrive>& drives, const VectorXd& w, const VectorXd& g_u,
                             VectorXd* g_w) {
  for (size_t s = 0; s < drives.size(); ++s) {
    const int c = drives[s].channel, sign = drives[s].sign;
    if (sign * w(c) > 0) (*g_w)(c) += sign * g_u(s);
  }
}

}  // namespace diffpd
