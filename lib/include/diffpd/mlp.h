// A small multilayer perceptron on Eigen, with its vector-Jacobian products:
// the policy network of closed-loop controllers (controller.h).
//
// Widths (n_0, n_1, ..., n_L): L affine layers y_l = W_l z_{l-1} + b_l,
// W_l n_l x n_{l-1}, z_0 the input, z_l = s(y_l) with s the hidden
// nonlinearity for l < L and the output nonlinearity for l = L.
//
// Parameters theta: layer by layer, W_l column-major (n_l * n_{l-1} entries)
// then b_l (n_l entries); num_parameters() = sum_l n_l (n_{l-1} + 1).
//
// Cost: one forward pass is sum_l n_l n_{l-1} multiply-adds, the backward
// pass twice that; nothing is allocated per call beyond the tape's vectors.
#pragma once

#include <cstdint>
#include <vector>

#include "diffpd/types.h"

namespace diffpd {

enum class MlpNonlinearity {
  kTanh,      // s(y) = tanh(y)
  kIdentity,  // s(y) = y
};

// The values of one forward pass that the backward pass needs: z_0..z_L.
struct MlpTape {
  std::vector<VectorXd> z;
};

class Mlp {
 public:
  // Throws InvalidInputError for fewer than two widths or a width < 1
  // ("Mlp: widths[2] = 0 is invalid: must be >= 1"). Parameters start at 0.
  explicit Mlp(std::vector<int> widths, MlpNonlinearity hidden = MlpNonlinearity::kTanh,
               MlpNonlinearity output = MlpNonlinearity::kIdentity);

  const std::vector<int>& widths() const { return widths_; }
  int num_layers() const { return static_cast<int>(widths_.size()) - 1; }
  int num_inputs() const { return widths_.front(); }
  int num_outputs() const { return widths_.back(); }
  int num_parameters() const { return static_cast<int>(theta_.size()); }

  const VectorXd& parameters() const { return theta_; }
  // Throws InvalidInputError for a wrong size or a non-finite entry
  // ("Mlp: parameters have 3 entries, expected 20").
  void SetParameters(const VectorXd& parameters);

  // Orthogonal weights and zero biases (Saxe et al. 2014, as
  // torch.nn.init.orthogonal_): W_l = gain Q, Q the n_l x n_{l-1} matrix
  // with orthonormal rows (n_l <= n_{l-1}) or columns from the QR
  // factorisation of a matrix of standard normal draws, signs fixed by R's
  // diagonal. Deterministic for a seed on every platform (mt19937_64 and
  // Box-Muller, no std:: distributions). Throws InvalidInputError for a
  // non-finite gain.
  void InitializeOrthogonal(std::uint64_t seed, double gain);

  // The output for `input` (num_inputs() entries; InvalidInputError for a
  // wrong size: "Mlp: input has 3 entries, expected 4").
  VectorXd Evaluate(const VectorXd& input) const;
  // The same, recording the tape for Backward.
  VectorXd Forward(const VectorXd& input, MlpTape* tape) const;
  // Reverse mode at the tape's point: given g = dL/d(output), sets
  // *g_input = dL/d(input) (if not nullptr) and adds dL/dtheta to
  // *g_parameters (num_parameters() entries; if not nullptr).
  void Backward(const MlpTape& tape, const VectorXd& g_output, VectorXd* g_input, VectorXd* g_parameters) const;

 private:
  MlpNonlinearity nonlinearity(int layer) const { return layer + 1 == num_layers() ? output_ : hidden_; }

  std::vector<int> widths_;
  MlpNonlinearity hidden_, output_;
  std::vector<int> offsets_;  // start of layer l's W in theta_
  VectorXd theta_;
};

}  // namespace diffpd
