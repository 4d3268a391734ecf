#include "core/multigrid/smoothing.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace tresca {

real lanczos_lmax(index n, const std::function<void(real*, real*)>& apply, const Field<real>& dinv,
                  Field<real> r, const Reduction* reduce) {
  // Lanczos through Jacobi-PCG: T_jj = 1/a_j + b_{j-1}/a_{j-1}, T_j,j+1 = sqrt(b_j)/a_j
  auto global = [&](real s) { return reduce ? reduce->sum(s) : s; };
  Field<real> x(n, 0), z(n), p(n), q(n);
  hadamard(n, dinv.data(), r.data(), z.data());
  copy(n, z.data(), p.data());
  real rz = global(dot(n, r.data(), z.data()));
  std::vector<real> al, be;
  const int its = 15;
  for (int j = 0; j < its && rz > 0; ++j) {
    apply(p.data(), q.data());
    const real a = rz / global(dot(n, p.data(), q.data()));
    cg_update(n, a, p.data(), q.data(), x.data(), r.data());
    hadamard(n, dinv.data(), r.data(), z.data());
    const real rz_new = global(dot(n, r.data(), z.data()));
    al.push_back(a);
    be.push_back(rz_new / rz);
    xpay(n, z.data(), rz_new / rz, p.data());
    rz = rz_new;
  }
  const int m = int(al.size());
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(m, m);
  for (int j = 0; j < m; ++j) {
    T(j, j) = 1 / al[j] + (j > 0 ? be[j - 1] / al[j - 1] : 0);
    if (j + 1 < m) T(j, j + 1) = T(j + 1, j) = std::sqrt(be[j]) / al[j];
  }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(T, Eigen::EigenvaluesOnly);
  // B terms of the Newton preconditioner (PSD, 2x2 blocks) keep D^{-1}(K+B) below max(lmax, 2)
  return 1.15 * std::max(es.eigenvalues().maxCoeff(), real(2));
}

std::vector<real> project_bottom_block(const Transfer& t, const std::vector<real>& Bf) {
  const GridDims &fg = t.fine, &cg = t.coarse;
  const index Mf = fg.nx() * fg.ny(), Mc = cg.nx() * cg.ny();
  const Interp1D &X = t.axis[0], &Y = t.axis[1];
  std::vector<real> Bc(4 * Mc, 0.0);
  for (int fld = 0; fld < 4; ++fld)
    for (index jy = 0; jy < cg.ny(); ++jy)
      for (index jx = 0; jx < cg.nx(); ++jx) {
        real s = 0;
        for (index ky = Y.tstart[jy]; ky < Y.tstart[jy + 1]; ++ky)
          for (index kx = X.tstart[jx]; kx < X.tstart[jx + 1]; ++kx)
            s += Y.tw[ky] * X.tw[kx] * Bf[fld * Mf + X.tf[kx] + fg.nx() * Y.tf[ky]];
        Bc[fld * Mc + jx + cg.nx() * jy] = s;
      }
  return Bc;
}

}  // namespace tresca
