#include "material/cofactor.h"

#include <Eigen/Geometry>

namespace diffpd::internal {
namespace {

// [a]_x b = a x b.
Mat3 CrossMatrix(const Vec3& a) {
  Mat3 m;
  m << 0.0, -a(2), a(1), a(2), 0.0, -a(0), -a(1), a(0), 0.0;
  return m;
}

}  // namespace

Mat3 Cofactor(const Mat3& F) {
  Mat3 C;
  C.col(0) = F.col(1).cross(F.col(2));
  C.col(1) = F.col(2).cross(F.col(0));
  C.col(2) = F.col(0).cross(F.col(1));
  return C;
}

Mat9 CofactorDifferential(const Mat3& F) {
  // c_a = f_{a+1} x f_{a+2}: d c_a = df_{a+1} x f_{a+2} + f_{a+1} x df_{a+2}.
  Mat9 D = Mat9::Zero();
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    D.block<3, 3>(3 * a, 3 * b) = -CrossMatrix(F.col(c));
    D.block<3, 3>(3 * a, 3 * c) = CrossMatrix(F.col(b));
  }
  return D;
}

}  // namespace diffpd::internal
