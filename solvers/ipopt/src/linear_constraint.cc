#include "diffpd/solvers/ipopt/linear_constraint.h"

#include <cmath>
#include <set>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {

void LinearConstraint::Validate(int num_variables) const {
  std::ostringstream msg;
  msg << "linear constraint '" << name << "': ";
  if (columns.size() != coefficients.size()) {
    msg << columns.size() << " columns but " << coefficients.size() << " coefficients";
    throw InvalidInputError(msg.str());
  }
  std::set<int> seen;
  for (size_t j = 0; j < columns.size(); ++j) {
    if (columns[j] < 0 || columns[j] >= num_variables) {
      msg << "column " << columns[j] << " is out of range [0, " << num_variables << ")";
      throw InvalidInputError(msg.str());
    }
    if (!seen.insert(columns[j]).second) {
      msg << "column " << columns[j] << " repeats";
      throw InvalidInputError(msg.str());
    }
    if (!std::isfinite(coefficients[j])) {
      msg << "coefficient " << j << " is not finite";
      throw InvalidInputError(msg.str());
    }
  }
  if (std::isnan(lower) || std::isnan(upper) || lower > upper) {
    msg << "bounds [" << lower << ", " << upper << "] are invalid: need lower <= upper, no NaN";
    throw InvalidInputError(msg.str());
  }
}

std::vector<LinearConstraint> SignalRangeConstraints(const ControlSignal& signal, int offset, double lower,
                                                     double upper, const std::string& name) {
  if (!signal.is_linear()) throw InvalidInputError(name + ": range constraints need a linear signal");
  const int p = signal.num_coefficients();
  MatrixXd basis;
  signal.Evaluate(VectorXd::Zero(p), nullptr, &basis);
  std::vector<LinearConstraint> rows;
  std::vector<Eigen::Index> kept;
  for (Eigen::Index k = 0; k < basis.rows(); ++k) {
    bool repeated = false;
    for (Eigen::Index r : kept)
      if ((basis.row(r) - basis.row(k)).cwiseAbs().maxCoeff() <= 1e-12 * (1 + basis.row(k).cwiseAbs().maxCoeff()))
        repeated = true;
    if (repeated) continue;
    kept.push_back(k);
    LinearConstraint c;
    c.name = name + "[" + std::to_string(k) + "]";
    c.lower = lower;
    c.upper = upper;
    for (int j = 0; j < p; ++j)
      if (basis(k, j) != 0) {
        c.columns.push_back(offset + j);
        c.coefficients.push_back(basis(k, j));
      }
    rows.push_back(std::move(c));
  }
  return rows;
}

}  // namespace diffpd::solvers
