#include "diffpd/solvers/core/parameter_block.h"

#include <cmath>
#include <limits>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {

ParameterBlock::ParameterBlock(int size) { Append(size); }

void ParameterBlock::Append(int count) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const Eigen::Index old = initial_.size();
  lower_.conservativeResize(old + count);
  upper_.conservativeResize(old + count);
  initial_.conservativeResize(old + count);
  lower_.tail(count).setConstant(-kInf);
  upper_.tail(count).setConstant(kInf);
  initial_.tail(count).setZero();
}

void ParameterBlock::SetBounds(double lower, double upper) { SetBounds(0, size(), lower, upper); }

void ParameterBlock::SetBounds(int offset, int count, double lower, double upper) {
  if (offset < 0 || count < 0 || offset + count > size()) {
    std::ostringstream msg;
    msg << name() << ": bounds for variables [" << offset << ", " << offset + count << ") are out of range [0, "
        << size() << ")";
    throw InvalidInputError(msg.str());
  }
  if (std::isnan(lower) || std::isnan(upper) || lower > upper) {
    std::ostringstream msg;
    msg << name() << ": bounds [" << lower << ", " << upper << "] are invalid: need lower <= upper, no NaN";
    throw InvalidInputError(msg.str());
  }
  lower_.segment(offset, count).setConstant(lower);
  upper_.segment(offset, count).setConstant(upper);
}

void ParameterBlock::SetInitial(const VectorXd& values) {
  if (values.size() != size() || !values.allFinite()) {
    std::ostringstream msg;
    msg << name() << ": starting values have " << values.size() << " entries (expected " << size() << ", all finite)";
    throw InvalidInputError(msg.str());
  }
  initial_ = values;
}

}  // namespace diffpd::solvers
