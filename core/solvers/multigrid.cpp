#include "core/solvers/multigrid.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "kernels/boundary_block.hpp"
#include "core/solvers/smoothing.hpp"
#include "kernels/vector_ops.hpp"
#include "core/util/profile.hpp"

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

const char* to_string(Precision p) { return p == Precision::single_precision ? "single" : "double"; }

std::shared_ptr<const GridHierarchy> GridHierarchy::build(const GridDims& fine, index coarse_nodes) {
  auto h = std::make_shared<GridHierarchy>();
  GridDims g = fine;
  for (;;) {
    h->grids.push_back(g);
    if (g.nodes() <= coarse_nodes || (g.ex == 1 && g.ey == 1 && g.ez == 1)) break;
    const GridDims coarse = coarsen(g);
    h->to_coarse.push_back(build_transfer(g, coarse));
    g = coarse;
  }
  return h;
}

Rediscretisation elasticity_on(unsigned faces, real E, real nu) {
  return [=](const GridDims& g) { return ElasticityOperator(g, faces, E, nu); };
}

Multigrid::Multigrid(const GridDims& fine, unsigned faces, real E, real nu, const MGOptions& opt)
    : Multigrid(GridHierarchy::build(fine, opt.coarse_nodes), elasticity_on(faces, E, nu), opt) {}

Multigrid::Multigrid(std::shared_ptr<const GridHierarchy> grids, const Rediscretisation& op, const MGOptions& opt)
    : Multigrid(std::move(grids), op, opt, nullptr) {}

Multigrid::Multigrid(std::shared_ptr<const GridHierarchy> grids, const Rediscretisation& op, const MGOptions& opt,
                     const Multigrid& like)
    : Multigrid(std::move(grids), op, opt, &like) {}

Multigrid::Multigrid(std::shared_ptr<const GridHierarchy> grids, const Rediscretisation& op, const MGOptions& opt,
                     const Multigrid* like)
    : opt_(opt), grids_(std::move(grids)) {
  if (!grids_ || grids_->grids.empty()) throw std::invalid_argument("multigrid: empty grid hierarchy");
  if (like && like->grids_ != grids_)
    throw std::invalid_argument("multigrid: spectral bounds can only be shared on the same hierarchy");
  for (const GridDims& g : grids_->grids) {
    Level lv;
    lv.A = op(g);
    if (lv.A.grid().nodes() != g.nodes())
      throw std::invalid_argument("multigrid: the rediscretised operator does not live on the hierarchy's grid");
    levels_.push_back(std::move(lv));
  }
  for (size_t l = 0; l + 1 < levels_.size(); ++l) {
    if (like)
      levels_[l].lmax = like->levels_[l].lmax;
    else
      estimate_lmax(levels_[l]);
  }
  factor_coarse();
  if (opt_.precision == Precision::single_precision)
    build_work<float>();
  else
    build_work<double>();
}

template <>
std::vector<Multigrid::Work<double>>& Multigrid::work<double>() {
  return work_d_;
}
template <>
std::vector<Multigrid::Work<float>>& Multigrid::work<float>() {
  return work_s_;
}
template <>
const std::vector<Multigrid::Work<double>>& Multigrid::work<double>() const {
  return work_d_;
}
template <>
const std::vector<Multigrid::Work<float>>& Multigrid::work<float>() const {
  return work_s_;
}

template <class T>
void Multigrid::build_work() {
  std::vector<Work<T>>& W = work<T>();
  W.resize(levels_.size());
  for (size_t l = 0; l < levels_.size(); ++l) {
    Work<T>& w = W[l];
    const index n = levels_[l].A.size();
    w.k = stencil_in_precision<T>(levels_[l].A.stencil());
    w.r.resize(n);
    w.d.resize(n);
    // a double level 0 solves in the caller's arrays (apply sets xp, bp)
    if (l > 0 || !std::is_same<T, real>::value) {
      w.x.resize(n);
      w.b.resize(n);
      w.xp = w.x.data();
      w.bp = w.b.data();
    }
  }
  refresh_work<T>();
}

template <class T>
void Multigrid::refresh_work() {
  std::vector<Work<T>>& W = work<T>();
  for (size_t l = 0; l < levels_.size(); ++l) {
    const std::vector<real> d = levels_[l].A.diagonal();
    W[l].dinv.resize(d.size());
    for (size_t i = 0; i < d.size(); ++i) W[l].dinv[i] = T(1 / d[i]);
    const std::vector<real>& B = levels_[l].A.bottom_block();
    W[l].B.assign(B.begin(), B.end());
  }
}

void Multigrid::estimate_lmax(Level& lv) {
  const index n = lv.A.size();
  std::vector<real> r(n), dinv = lv.A.diagonal();
  for (real& v : dinv) v = 1 / v;
  std::uint64_t s = 12345;
  for (index i = 0; i < n; ++i) {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    r[i] = real((s >> 11) & 0xFFFFF) / real(0xFFFFF) - 0.5;
  }
  zero_constrained(lv.A.grid(), lv.A.faces(), r.data());
  lv.lmax = lanczos_lmax(n, [&](const real* p, real* q) { lv.A.apply(p, q); }, dinv, std::move(r));
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
    std::vector<real> Bc = project_bottom_block(grids_->to_coarse[l], Bf);
    c.A.set_bottom_block(std::move(Bc));
  }
  factor_coarse();
  if (opt_.precision == Precision::single_precision)
    refresh_work<float>();
  else
    refresh_work<double>();
}

template <class T>
void Multigrid::residual(int l, const T* b, const T* x, T* r) const {
  const Work<T>& w = work<T>()[l];
  const GridDims& g = w.k.g;
  {
    const double nodes = double(g.nodes());
    ScopedTimer t(Kernel::apply, nodes * in_precision<T>(kResidualCost));
    elasticity_apply<T>(w.k, x, r, 0, g.nz(), b);
  }
  if (!w.B.empty()) {
    const double m = double(g.nx()) * double(g.ny());
    ScopedTimer t(Kernel::apply_boundary, m * in_precision<T>(kBottomBlockCost));
    bottom_block_apply<T>(g, T(-1), w.B.data(), x, r);
  }
}

template <class T>
void Multigrid::smooth(int l, bool zero_guess) const {
  const Work<T>& w = work<T>()[l];
  ScopedTimer t(Kernel::smoother);
  chebyshev_smooth<T>(levels_[l].A.size(), levels_[l].lmax, opt_.range, opt_.degree, zero_guess, w.dinv.data(), w.bp,
                      w.xp, w.r.data(), w.d.data(), [&](const T* x, T* r) { residual<T>(l, w.bp, x, r); });
}

template <class T>
void Multigrid::vcycle(int l) const {
  const Work<T>& w = work<T>()[l];
  const Level& lv = levels_[l];
  const index n = lv.A.size();
  if (l + 1 == int(levels_.size())) {
    ScopedTimer t(Kernel::coarse_solve);
    for (index i = 0; i < n; ++i) cb_[i] = real(w.bp[i]);
    cx_ = coarse_.solve(cb_);
    for (index i = 0; i < n; ++i) w.xp[i] = T(cx_[i]);
    return;
  }
  const Work<T>& c = work<T>()[l + 1];
  const GridDims& cg = levels_[l + 1].A.grid();
  smooth<T>(l, true);
  residual<T>(l, w.bp, w.xp, w.r.data());
  {
    const double nf = double(n);
    ScopedTimer t(Kernel::restrict_, nf * in_precision<T>(kRestrictCost));
    restrict_to_coarse<T>(grids_->to_coarse[l], 3, w.r.data(), c.b.data());
    zero_constrained<T>(cg, lv.A.faces(), c.b.data());
  }
  vcycle<T>(l + 1);
  {
    // x += P x_c; the correction vanishes on constrained faces (they are
    // interpolated from constrained coarse nodes only), the mask makes it exact
    const double nf = double(n);
    ScopedTimer t(Kernel::prolongate, nf * in_precision<T>(kProlongateCost));
    prolongate<T>(grids_->to_coarse[l], 3, c.x.data(), w.xp, true);
    zero_constrained<T>(lv.A.grid(), lv.A.faces(), w.xp);
  }
  smooth<T>(l, false);
}

void Multigrid::apply(const real* r, real* z) const {
  const index n = size();
  if (opt_.precision == Precision::double_precision) {
    work_d_[0].bp = r;
    work_d_[0].xp = z;
    vcycle<double>(0);
  } else {
    const Work<float>& w = work_s_[0];
    convert<float>(n, r, w.b.data());
    vcycle<float>(0);
    convert<double>(n, w.x.data(), z);
  }
}

double Multigrid::cycle_work() const {
  double w = 0;
  for (size_t l = 0; l + 1 < levels_.size(); ++l) w += double(levels_[l].A.grid().nodes());
  return 2.0 * opt_.degree * w / double(levels_[0].A.grid().nodes());
}

std::string Multigrid::describe() const {
  std::ostringstream os;
  os << levels_.size() << " levels:";
  for (const auto& lv : levels_) {
    const GridDims& g = lv.A.grid();
    os << " " << g.ex << "x" << g.ey << "x" << g.ez;
  }
  os << " (" << to_string(opt_.precision) << " precision)";
  return os.str();
}

}  // namespace tresca
