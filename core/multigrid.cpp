#include "multigrid.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "../kernels/vector_ops.hpp"
#include "profile.hpp"

namespace tresca {

namespace {
// Semi-coarsening: halve (rounding up) only the axes whose spacing is within
// 1.5x of the finest one, so that anisotropic bricks become isotropic on the
// coarse grids instead of flatter. Near-isotropic grids coarsen in all axes.
GridDims coarsen(const GridDims& g) {
  index* e[3] = {nullptr, nullptr, nullptr};
  GridDims c = g;
  e[0] = &c.ex;
  e[1] = &c.ey;
  e[2] = &c.ez;
  const real h[3] = {g.hx(), g.hy(), g.hz()};
  real hmin = INFINITY;
  for (int a = 0; a < 3; ++a)
    if (*e[a] > 1) hmin = std::min(hmin, h[a]);
  for (int a = 0; a < 3; ++a)
    if (*e[a] > 1 && h[a] <= 1.5 * hmin) *e[a] = (*e[a] + 1) / 2;
  return c;
}
}  // namespace

Multigrid::Multigrid(const GridDims& fine, unsigned faces, real E, real nu, const MGOptions& opt) : opt_(opt) {
  GridDims g = fine;
  for (;;) {
    Level lv;
    lv.A = ElasticityOperator(g, faces, E, nu);
    const index n = lv.A.size();
    if (!levels_.empty()) {  // level 0 solves in the caller's arrays
      lv.x.resize(n);
      lv.b.resize(n);
    }
    lv.r.resize(n);
    lv.d.resize(n);
    const bool last = g.nodes() <= opt.coarse_nodes || (g.ex == 1 && g.ey == 1 && g.ez == 1);
    const GridDims coarse = last ? g : coarsen(g);
    if (!last) lv.to_coarse = build_transfer(g, coarse);
    levels_.push_back(std::move(lv));
    if (levels_.size() > 1) {
      levels_.back().xp = levels_.back().x.data();
      levels_.back().bp = levels_.back().b.data();
    }
    if (last) break;
    g = coarse;
  }
  refresh_diagonals();
  for (size_t l = 0; l + 1 < levels_.size(); ++l) estimate_lmax(levels_[l]);
  factor_coarse();
}

void Multigrid::refresh_diagonals() {
  for (auto& lv : levels_) {
    const std::vector<real> d = lv.A.diagonal();
    lv.dinv.resize(d.size());
    for (size_t i = 0; i < d.size(); ++i) lv.dinv[i] = 1 / d[i];
  }
}

void Multigrid::estimate_lmax(Level& lv) {
  // Lanczos through Jacobi-PCG: T_jj = 1/a_j + b_{j-1}/a_{j-1}, T_j,j+1 = sqrt(b_j)/a_j
  const index n = lv.A.size();
  std::vector<real> x(n, 0), r(n), z(n), p(n), q(n);
  std::uint64_t s = 12345;
  for (index i = 0; i < n; ++i) {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    r[i] = real((s >> 11) & 0xFFFFF) / real(0xFFFFF) - 0.5;
  }
  zero_constrained(lv.A.grid(), lv.A.faces(), r.data());
  hadamard(n, lv.dinv.data(), r.data(), z.data());
  copy(n, z.data(), p.data());
  real rz = dot(n, r.data(), z.data());
  std::vector<real> al, be;
  const int its = 15;
  for (int j = 0; j < its && rz > 0; ++j) {
    lv.A.apply(p.data(), q.data());
    const real a = rz / dot(n, p.data(), q.data());
    cg_update(n, a, p.data(), q.data(), x.data(), r.data());
    hadamard(n, lv.dinv.data(), r.data(), z.data());
    const real rz_new = dot(n, r.data(), z.data());
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
  lv.lmax = 1.15 * std::max(es.eigenvalues().maxCoeff(), real(2));
}

void Multigrid::factor_coarse() {
  SparseMatrix A = assemble(levels_.back().A);
  coarse_.compute(A);
  if (coarse_.info() != Eigen::Success) throw std::runtime_error("multigrid: coarse factorisation failed");
  cb_.resize(A.rows());
  cx_.resize(A.rows());
}

void Multigrid::set_bottom_block(const std::vector<real>& B) {
  levels_[0].A.set_bottom_block(B);
  for (size_t l = 0; l + 1 < levels_.size(); ++l) {
    const Level& f = levels_[l];
    Level& c = levels_[l + 1];
    const std::vector<real>& Bf = f.A.bottom_block();
    if (Bf.empty()) {
      c.A.set_bottom_block({});
      continue;
    }
    const GridDims &fg = f.A.grid(), &cg = c.A.grid();
    const index Mf = fg.nx() * fg.ny(), Mc = cg.nx() * cg.ny();
    const Interp1D &X = f.to_coarse.axis[0], &Y = f.to_coarse.axis[1];
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
    c.A.set_bottom_block(std::move(Bc));
  }
  refresh_diagonals();
  factor_coarse();
}

void Multigrid::smooth(int l, bool zero_guess) const {
  const Level& lv = levels_[l];
  const index n = lv.A.size();
  ScopedTimer t(Kernel::smoother);
  const real lmax = lv.lmax, lmin = lmax / opt_.range;
  const real theta = (lmax + lmin) / 2, delta = (lmax - lmin) / 2, sigma = theta / delta;
  real* x = lv.xp;
  real* r = lv.r.data();
  real* d = lv.d.data();
  if (zero_guess) {
    cheb_first(n, 1 / theta, lv.dinv.data(), lv.bp, d, x);
  } else {
    lv.A.residual(lv.bp, x, r);
    fill(n, 0, d);
    cheb_update(n, 0, 1 / theta, lv.dinv.data(), r, d, x);
  }
  real rho = 1 / sigma;
  for (int k = 1; k < opt_.degree; ++k) {
    lv.A.residual(lv.bp, x, r);
    const real rho_new = 1 / (2 * sigma - rho);
    cheb_update(n, rho_new * rho, 2 * rho_new / delta, lv.dinv.data(), r, d, x);
    rho = rho_new;
  }
}

void Multigrid::vcycle(int l) const {
  const Level& lv = levels_[l];
  const index n = lv.A.size();
  if (l + 1 == int(levels_.size())) {
    ScopedTimer t(Kernel::coarse_solve);
    for (index i = 0; i < n; ++i) cb_[i] = lv.bp[i];
    cx_ = coarse_.solve(cb_);
    for (index i = 0; i < n; ++i) lv.xp[i] = cx_[i];
    return;
  }
  const Level& c = levels_[l + 1];
  smooth(l, true);
  lv.A.residual(lv.bp, lv.xp, lv.r.data());
  {
    const double nf = double(n);
    ScopedTimer t(Kernel::restrict_, nf * kRestrictCost);
    restrict_to_coarse(lv.to_coarse, 3, lv.r.data(), c.b.data());
    zero_constrained(c.A.grid(), c.A.faces(), c.b.data());
  }
  vcycle(l + 1);
  {
    // x += P x_c; the correction vanishes on constrained faces (they are
    // interpolated from constrained coarse nodes only), the mask makes it exact
    const double nf = double(n);
    ScopedTimer t(Kernel::prolongate, nf * kProlongateCost);
    prolongate(lv.to_coarse, 3, c.x.data(), lv.xp, true);
    zero_constrained(lv.A.grid(), lv.A.faces(), lv.xp);
  }
  smooth(l, false);
}

void Multigrid::apply(const real* r, real* z) const {
  levels_[0].bp = r;
  levels_[0].xp = z;
  vcycle(0);
}

std::string Multigrid::describe() const {
  std::ostringstream os;
  os << levels_.size() << " levels:";
  for (const auto& lv : levels_) {
    const GridDims& g = lv.A.grid();
    os << " " << g.ex << "x" << g.ey << "x" << g.ez;
  }
  return os.str();
}

}  // namespace tresca
