#include "diffpd/mlp.h"

#include <cmath>
#include <limits>
#include <random>
#include <sstream>

#include <Eigen/QR>

#include "diffpd/error.h"

namespace diffpd {
namespace {

// Standard normal draws from mt19937_64 by Box-Muller (portable: the
// std:: distributions differ between standard libraries).
class NormalDraws {
 public:
  explicit NormalDraws(std::uint64_t seed) : engine_(seed) {}
  double Next() {
    if (have_spare_) {
      have_spare_ = false;
      return spare_;
    }
    // u1 in (0, 1], u2 in [0, 1), from the top 53 bits.
    const double u1 = (static_cast<double>(engine_() >> 11) + 1.0) * 0x1.0p-53;
    const double u2 = static_cast<double>(engine_() >> 11) * 0x1.0p-53;
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2 * M_PI * u2);
    have_spare_ = true;
    return r * std::cos(2 * M_PI * u2);
  }

 private:
  std::mt19937_64 engine_;
  double spare_ = 0;
  bool have_spare_ = false;
};

void Apply(MlpNonlinearity s, VectorXd* y) {
  if (s == MlpNonlinearity::kTanh) *y = y->array().tanh();
}

}  // namespace

Mlp::Mlp(std::vector<int> widths, MlpNonlinearity hidden, MlpNonlinearity output)
    : widths_(std::move(widths)), hidden_(hidden), output_(output) {
  if (widths_.size() < 2) {
    std::ostringstream msg;
    msg << "Mlp: " << widths_.size() << " widths given, need at least 2 (inputs and outputs)";
    throw InvalidInputError(msg.str());
  }
  for (size_t l = 0; l < widths_.size(); ++l)
    if (widths_[l] < 1) {
      std::ostringstream msg;
      msg << "Mlp: widths[" << l << "] = " << widths_[l] << " is invalid: must be >= 1";
      throw InvalidInputError(msg.str());
    }
  int size = 0;
  for (int l = 0; l < num_layers(); ++l) {
    offsets_.push_back(size);
    size += widths_[l + 1] * (widths_[l] + 1);
  }
  theta_ = VectorXd::Zero(size);
}

void Mlp::SetParameters(const VectorXd& parameters) {
  if (parameters.size() != theta_.size()) {
    std::ostringstream msg;
    msg << "Mlp: parameters have " << parameters.size() << " entries, expected " << theta_.size();
    throw InvalidInputError(msg.str());
  }
  if (!parameters.allFinite()) throw InvalidInputError("Mlp: parameters have a non-finite entry");
  theta_ = parameters;
}

void Mlp::InitializeOrthogonal(std::uint64_t seed, double gain) {
  if (!std::isfinite(gain)) {
    std::ostringstream msg;
    msg << "Mlp: gain = " << gain << " is invalid: must be finite";
    throw InvalidInputError(msg.str());
  }
  NormalDraws normal(seed);
  theta_.setZero();
  for (int l = 0; l < num_layers(); ++l) {
    const int rows = widths_[l + 1], cols = widths_[l];
    // Q of a tall matrix (max x min), transposed when the layer is wide.
    const bool wide = rows < cols;
    const int tall = wide ? cols : rows, narrow = wide ? rows : cols;
    MatrixXd a(tall, narrow);
    for (int j = 0; j < narrow; ++j)
      for (int i = 0; i < tall; ++i) a(i, j) = normal.Next();
    const Eigen::HouseholderQR<MatrixXd> qr(a);
    MatrixXd q = qr.householderQ() * MatrixXd::Identity(tall, narrow);
    const MatrixXd r = qr.matrixQR().topRows(narrow).triangularView<Eigen::Upper>();
    for (int j = 0; j < narrow; ++j)
      if (r(j, j) < 0) q.col(j) = -q.col(j);
    Eigen::Map<MatrixXd> w(theta_.data() + offsets_[l], rows, cols);
    if (wide)
      w = gain * q.transpose();
    else
      w = gain * q;
  }
}

VectorXd Mlp::Evaluate(const VectorXd& input) const {
  MlpTape tape;
  return Forward(input, &tape);
}

VectorXd Mlp::Forward(const VectorXd& input, MlpTape* tape) const {
  if (input.size() != num_inputs()) {
    std::ostringstream msg;
    msg << "Mlp: input has " << input.size() << " entries, expected " << num_inputs();
    throw InvalidInputError(msg.str());
  }
  tape->z.resize(num_layers() + 1);
  tape->z[0] = input;
  for (int l = 0; l < num_layers(); ++l) {
    const int rows = widths_[l + 1], cols = widths_[l];
    const Eigen::Map<const MatrixXd> w(theta_.data() + offsets_[l], rows, cols);
    const Eigen::Map<const VectorXd> b(theta_.data() + offsets_[l] + rows * cols, rows);
    VectorXd& y = tape->z[l + 1];
    y.noalias() = w * tape->z[l];
    y += b;
    Apply(nonlinearity(l), &y);
  }
  return tape->z.back();
}

void Mlp::Backward(const MlpTape& tape, const VectorXd& g_output, VectorXd* g_input, VectorXd* g_parameters) const {
  DIFFPD_CHECK(static_cast<int>(tape.z.size()) == num_layers() + 1,
               "Mlp::Backward: the tape has " << tape.z.size() << " entries");
  DIFFPD_CHECK(g_output.size() == num_outputs(), "Mlp::Backward: g_output has " << g_output.size() << " entries");
  DIFFPD_CHECK(!g_parameters || g_parameters->size() == num_parameters(),
               "Mlp::Backward: g_parameters has " << g_parameters->size() << " entries");
  VectorXd g = g_output;  // dL/dz_l
  for (int l = num_layers() - 1; l >= 0; --l) {
    const int rows = widths_[l + 1], cols = widths_[l];
    // dL/dy_l from dL/dz_l: tanh' = 1 - tanh^2.
    if (nonlinearity(l) == MlpNonlinearity::kTanh) g.array() *= 1.0 - tape.z[l + 1].array().square();
    if (g_parameters) {
      Eigen::Map<MatrixXd> gw(g_parameters->data() + offsets_[l], rows, cols);
      gw.noalias() += g * tape.z[l].transpose();
      g_parameters->segment(offsets_[l] + rows * cols, rows) += g;
    }
    if (l == 0 && !g_input) break;
    const Eigen::Map<const MatrixXd> w(theta_.data() + offsets_[l], rows, cols);
    VectorXd g_prev;
    g_prev.noalias() = w.transpose() * g;
    g = std::move(g_prev);
  }
  if (g_input) *g_input = std::move(g);
}

}  // namespace diffpd
