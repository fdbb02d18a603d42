// The error of a command-line tool's option that is out of its range.
#pragma once

#include <sstream>
#include <string>

#include "diffpd/error.h"

namespace diffpd::problems {

// Throws InvalidInputError("<field> = <value> is invalid: must be <range>").
[[noreturn]] inline void ThrowInvalidOption(const std::string& field, double value, const std::string& range) {
  std::ostringstream msg;
  msg << field << " = " << value << " is invalid: must be " << range;
  throw InvalidInputError(msg.str());
}

}  // namespace diffpd::problems
