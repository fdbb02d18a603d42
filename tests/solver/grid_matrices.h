// Sparse SPD test matrices on regular grids (tests of the sparse solvers).
#pragma once

#include <vector>

#include "diffpd/types.h"

namespace diffpd::internal {

// The 3D grid Laplacian (n^3 unknowns) plus shift * I: SPD for shift > 0.
inline SparseMatrix GridMatrix(int n, double shift) {
  const int size = n * n * n;
  std::vector<Eigen::Triplet<double>> t;
  auto id = [n](int i, int j, int k) { return (i * n + j) * n + k; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const int r = id(i, j, k);
        t.emplace_back(r, r, 6.0 + shift);
        if (i + 1 < n) t.emplace_back(r, id(i + 1, j, k), -1.0), t.emplace_back(id(i + 1, j, k), r, -1.0);
        if (j + 1 < n) t.emplace_back(r, id(i, j + 1, k), -1.0), t.emplace_back(id(i, j + 1, k), r, -1.0);
        if (k + 1 < n) t.emplace_back(r, id(i, j, k + 1), -1.0), t.emplace_back(id(i, j, k + 1), r, -1.0);
      }
  SparseMatrix a(size, size);
  a.setFromTriplets(t.begin(), t.end());
  return a;
}

// A 27-point stencil on an nx x ny x nz node grid (a hexahedral mesh's
// Laplacian pattern, as in the PD matrix) plus shift * I.
inline SparseMatrix HexGridMatrix(int nx, int ny, int nz, double shift) {
  std::vector<Eigen::Triplet<double>> t;
  auto id = [&](int i, int j, int k) { return (i * ny + j) * nz + k; };
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k)
        for (int di = -1; di <= 1; ++di)
          for (int dj = -1; dj <= 1; ++dj)
            for (int dk = -1; dk <= 1; ++dk) {
              const int a = i + di, b = j + dj, c = k + dk;
              if (a < 0 || b < 0 || c < 0 || a >= nx || b >= ny || c >= nz) continue;
              const bool diagonal = di == 0 && dj == 0 && dk == 0;
              t.emplace_back(id(i, j, k), id(a, b, c), diagonal ? 26.0 + shift : -1.0);
            }
  SparseMatrix m(nx * ny * nz, nx * ny * nz);
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

}  // namespace diffpd::internal
