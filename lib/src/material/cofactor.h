// Cofactor matrix of a 3x3 matrix and its differential (internal).
#pragma once

#include "diffpd/types.h"

namespace diffpd::internal {

// cof(F) = det(F) F^-T = [f1 x f2, f2 x f0, f0 x f1] (columns; f_i the columns
// of F), defined for every F; d det F / dF = cof(F).
Mat3 Cofactor(const Mat3& F);
// d vec(cof F) / d vec(F) (9x9, column-major flattening): block (a, b) is
// d c_a / d f_b, e.g. d c_0 / d f_1 = -[f_2]_x, d c_0 / d f_2 = [f_1]_x.
Mat9 CofactorDifferential(const Mat3& F);

}  // namespace diffpd::internal
