#include "core/multigrid/smoothing.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace tresca {

template <class T>
real lanczos_lmax(index n, const std::function<void(T*, T*)>& apply, const Field<T>& dinv, Field<T> r,
                  const Reduction* reduce) {
  // Lanczos through Jacobi-PCG: T_jj = 1/a_j + b_{j-1}/a_{j-1}, T_j,j+1 = sqrt(b_j)/a_j,
  // with a_j, b_j as the vectors' precision holds them (the coefficients of
  // the recursion actually run); the iterate itself is not needed
  auto global = [&](real s) { return reduce ? reduce->sum(s) : s; };
  Field<T> p(n), q(n);  // (zeros)
  // r.(D^-1 r), the update by a = 0; p = D^-1 r
  real rz = global(jacobi_cg_update<T>(n, 0, p.data(), dinv.data(), r.data()));
  jacobi_xpay<T>(n, dinv.data(), r.data(), 0, p.data());
  std::vector<real> al, be;
  const int its = 15;
  for (int j = 0; j < its && rz > 0; ++j) {
    apply(p.data(), q.data());
    const real pq = global(dot(n, p.data(), q.data()));
    if (!(pq > 0)) break;  // (p in A's null space, or A not positive: the steps so far)
    const T a = T(rz / pq);
    const real rz_new = global(jacobi_cg_update(n, a, q.data(), dinv.data(), r.data()));
    const T b = T(rz_new / rz);
    al.push_back(a);
    be.push_back(b);
    jacobi_xpay(n, dinv.data(), r.data(), b, p.data());
    rz = rz_new;
  }
  // B terms of the Newton preconditioner (PSD, 2x2 blocks) keep D^{-1}(K+B)
  // below max(lmax, 2); no step at all (no free entry): D^{-1}A = I
  constexpr real kSafety = 1.15, kFloor = 2;
  const int m = int(al.size());
  real largest = kFloor;
  if (m > 0) {
    Eigen::MatrixXd Tm = Eigen::MatrixXd::Zero(m, m);
    for (int j = 0; j < m; ++j) {
      Tm(j, j) = 1 / al[j] + (j > 0 ? be[j - 1] / al[j - 1] : 0);
      if (j + 1 < m) Tm(j, j + 1) = Tm(j + 1, j) = std::sqrt(be[j]) / al[j];
    }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Tm, Eigen::EigenvaluesOnly);
    largest = std::max(es.eigenvalues().maxCoeff(), kFloor);
  }
  return kSafety * largest;
}

template real lanczos_lmax<double>(index, const std::function<void(double*, double*)>&, const Field<double>&,
                                   Field<double>, const Reduction*);
template real lanczos_lmax<float>(index, const std::function<void(float*, float*)>&, const Field<float>&,
                                  Field<float>, const Reduction*);

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
