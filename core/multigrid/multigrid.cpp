#include "core/multigrid/multigrid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "kernels/boundary_block.hpp"
#include "kernels/launch.hpp"
#include "kernels/vector_ops.hpp"
#include "core/multigrid/smoothing.hpp"
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

// dinv = 1 / diag(A) in precision T where the launches run (0 on ghost
// rows), in dinv's own storage where it has the size already (each Newton
// step's bottom block refreshes it: no new block)
template <class T>
void inverse_diagonal(const ElasticityOperator& A, Field<T>& dinv) {
  const Field<real> d = A.diagonal();
  dinv.resize(d.size());
  reciprocal_or_zero<T>(index(d.size()), d.data(), dinv.data());
}

// local rows [first, last) of slab s as global rows
void row_range(const Slab& s, index& first, index& last) {
  first = s.y_begin - s.lo;
  last = s.y_end + s.hi;
}

// The link from level f to level c on this rank: the sliced transfers and
// the row fetches between split levels.
GridHierarchy::Link make_link(const Transfer& T, const GridHierarchy::Level& f, const GridHierarchy::Level& c,
                              const Comm& comm) {
  GridHierarchy::Link k;
  k.restrict_t = k.prolong_t = T;
  k.whole = T;
  k.whole.move_to(Space::host);
  if (!f.distributed) return k;  // both whole
  const Interp1D& Y = T.axis[1];
  index f0, f1, c0, c1;
  row_range(f.slab, f0, f1);
  row_range(c.slab, c0, c1);
  if (!c.distributed) k.prolong_t = slice_rows(T, f0, f1, 0, c.grid.ny());  // the coarse vector is whole here
  // restriction onto the coarse local rows [c0, c1): the fine rows of their
  // lists (onto a whole level: all of them, on rank 0 alone)
  index a = f.grid.ny(), b = 0;
  for (index j = c0; j < c1; ++j)
    for (index t = Y.tstart[j]; t < Y.tstart[j + 1]; ++t) a = std::min(a, Y.tf[t]), b = std::max(b, Y.tf[t] + 1);
  if (b - a < 2) b = std::min(f.grid.ny(), a + 2), a = b - 2;
  if (!c.distributed && comm.rank() != 0) a = b = 0;
  k.fetch_fine = std::make_shared<RowFetch>(f.slab, a, b, comm);
  if (a == b) return k;  // (prolong_t above: the coarse vector is whole on every rank)
  k.restrict_t = slice_rows(T, a, b, c0, c1);
  // prolongation onto the fine local rows [f0, f1): the coarse rows they interpolate from
  index ca = c.grid.ny(), cb = 0;
  for (index i = f0; i < f1; ++i) ca = std::min(ca, Y.j0[i]), cb = std::max(cb, Y.j0[i] + 2);
  cb = std::min(cb, c.grid.ny());
  if (cb - ca < 2) ca = cb - 2;
  if (c.distributed) {
    k.fetch_coarse = std::make_shared<RowFetch>(c.slab, ca, cb, comm);
    k.prolong_t = slice_rows(T, f0, f1, ca, cb);
  }
  return k;
}

// The Lanczos start vector's entry for global dof k: the (k+1)-th state of
// a 64-bit linear congruential sequence from 12345, reached by jumping ahead
// (so any rank's part of it is the same as the whole vector's).
struct Lcg {
  static constexpr std::uint64_t a = 6364136223846793005ULL, c = 1442695040888963407ULL;
  // the state after n steps from s
  static std::uint64_t jump(std::uint64_t s, std::uint64_t n) {
    std::uint64_t A = 1, C = 0, ma = a, mc = c;  // (A, C): the map so far; (ma, mc): 2^i steps
    for (; n; n >>= 1) {
      if (n & 1) A = ma * A, C = ma * C + mc;
      mc = ma * mc + mc;
      ma = ma * ma;
    }
    return A * s + C;
  }
  static real value(std::uint64_t s) { return real((s >> 11) & 0xFFFFF) / real(0xFFFFF) - 0.5; }
};

}  // namespace

const char* to_string(Precision p) { return p == Precision::single_precision ? "single" : "double"; }

bool worth_distributing(const GridDims& g, const Comm& comm, index min_nodes_per_rank) {
  const int P = comm.size();
  return P > 1 && g.ny() >= 2 * P && g.nodes() / P >= min_nodes_per_rank;
}

const Comm& split_over(const GridDims& g, const Comm& comm) {
  return worth_distributing(g, comm) ? comm : Comm::self();
}

std::string rank_layout(const GridDims& g, const Comm& comm, const std::string& whole) {
  if (!comm.distributed()) return "one rank";
  if (worth_distributing(g, comm)) return "y-slabs";
  return whole + ": too small to split, under 2 node rows in y or " + std::to_string(kMinNodesPerRank) +
         " nodes a rank";
}

std::vector<GridDims> coarsening(const GridDims& fine, index coarse_nodes) {
  std::vector<GridDims> grids;
  GridDims g = fine;
  for (;;) {
    grids.push_back(g);
    if (g.nodes() <= coarse_nodes || (g.ex == 1 && g.ey == 1 && g.ez == 1)) break;
    g = coarsen(g);
  }
  return grids;
}

real unresolved_anisotropy(const GridDims& fine, index coarse_nodes) {
  for (const GridDims& g : coarsening(fine, coarse_nodes)) {
    const index e[3] = {g.ex, g.ey, g.ez};
    const real h[3] = {g.hx(), g.hy(), g.hz()};
    const int thin = int(std::min_element(h, h + 3) - h);
    if (e[thin] > 1) continue;  // (the thin axis still coarsens)
    real worst = 1;
    for (int a = 0; a < 3; ++a)
      if (e[a] > 1) worst = std::max(worst, h[a] / h[thin]);
    return worst;
  }
  return 1;
}

std::shared_ptr<const GridHierarchy> GridHierarchy::build(const GridDims& fine, index coarse_nodes, const Comm& comm,
                                                          index min_nodes_per_rank,
                                                          std::optional<index> device_min_nodes) {
  auto h = std::make_shared<GridHierarchy>();
  h->comm = &comm;
  h->space = launch_space();
  const bool device = launch_on_device() && !comm.distributed();
  const index host_below = !device ? 0 : device_min_nodes ? *device_min_nodes : tresca::device_min_nodes();
  const std::vector<GridDims> grids = coarsening(fine, coarse_nodes);
  bool whole = false;  // once a level is whole, so are the coarser ones
  for (size_t l = 0; l < grids.size(); ++l) {
    Level lv;
    lv.grid = grids[l];
    const bool coarsest = l + 1 == grids.size();  // solved by a factorisation
    whole = whole || coarsest || !worth_distributing(lv.grid, comm, min_nodes_per_rank);
    lv.distributed = !whole;
    lv.slab = lv.distributed ? make_slab(lv.grid, comm.rank(), comm.size()) : make_slab(lv.grid, 0, 1);
    // (nodes fall from level to level: once a level is on the host, so are the coarser ones)
    lv.on_host = l > 0 && lv.grid.nodes() < host_below;
    h->levels.push_back(lv);
  }
  for (size_t l = 0; l + 1 < h->levels.size(); ++l) {
    // the transfers where level l's V-cycle runs them (the fine side's launches)
    const HostLaunches host(h->levels[l].on_host);
    h->to_coarse.push_back(make_link(build_transfer(grids[l], grids[l + 1]), h->levels[l], h->levels[l + 1], comm));
  }
  return h;
}

std::vector<GridDims> GridHierarchy::grids() const {
  std::vector<GridDims> g;
  for (const Level& lv : levels) g.push_back(lv.grid);
  return g;
}

bool GridHierarchy::agglomerated(int l) const {
  return comm->distributed() && !levels[l].distributed && (l == 0 || levels[l - 1].distributed);
}

int GridHierarchy::distributed_levels() const {
  int k = 0;
  for (const Level& lv : levels) k += lv.distributed ? 1 : 0;
  return k;
}

Rediscretisation elasticity_on(unsigned faces, real E, real nu) {
  return [=](const Slab& s) { return ElasticityOperator(s, faces, E, nu); };
}

Multigrid::Multigrid(const GridDims& fine, unsigned faces, real E, real nu, const MGOptions& opt, const Comm& comm)
    : Multigrid(GridHierarchy::build(fine, opt.coarse_nodes, comm), elasticity_on(faces, E, nu), opt) {}

Multigrid::Multigrid(std::shared_ptr<const GridHierarchy> grids, const Rediscretisation& op, const MGOptions& opt,
                     const Multigrid* like, const Rediscretisation& bounds_of)
    : opt_(opt), grids_(std::move(grids)) {
  if (!grids_ || grids_->levels.empty()) throw std::invalid_argument("multigrid: empty grid hierarchy");
  if (like && like->grids_ != grids_)
    throw std::invalid_argument("multigrid: spectral bounds can only be shared on the same hierarchy");
  if (grids_->space != launch_space())
    throw std::logic_error(std::string("multigrid: its grid hierarchy was built with the launches on the ") +
                           to_string(grids_->space) + ", the multigrid with them on the " + to_string(launch_space()));
  for (const GridHierarchy::Level& h : grids_->levels) {
    const HostLaunches where(h.on_host);  // each level made where it runs
    Level lv;
    lv.A = op(h.slab);
    if (lv.A.grid().nodes() != h.slab.local.nodes())
      throw std::invalid_argument("multigrid: the rediscretised operator does not live on the hierarchy's grid");
    levels_.push_back(std::move(lv));
  }
  // the smoother's bounds, in the V-cycle's precision: borrowed, or
  // estimated on bounds_of before this multigrid's work vectors exist (so
  // the estimate's own vectors add nothing to the peak), or on op with the
  // inverse diagonal of the work
  auto setup = [&](auto zero) {
    using T = decltype(zero);
    for (int l = 0; l + 1 < num_levels(); ++l) {
      if (like) {
        levels_[l].lmax = like->levels_[l].lmax;
      } else if (bounds_of) {
        const HostLaunches where(on_host(std::size_t(l)));
        const ElasticityOperator A = bounds_of(grids_->levels[l].slab);
        Field<T> dinv;
        inverse_diagonal(A, dinv);
        levels_[l].lmax = estimate_lmax<T>(l, A, dinv);
      }
    }
    build_work<T>(like);
    if (!like && !bounds_of)
      for (int l = 0; l + 1 < num_levels(); ++l)
        levels_[l].lmax = estimate_lmax<T>(l, levels_[l].A, held<T>().dinv[std::size_t(l)]);
  };
  if (opt_.precision == Precision::single_precision)
    setup(float{});
  else
    setup(double{});
  factor_coarse();
}

template <class T>
void Multigrid::build_work(const Multigrid* like) {
  std::shared_ptr<Cycle<T>>& C = held<T>().cycle;
  if (like && like->held<T>().cycle) {
    C = like->held<T>().cycle;  // (the same hierarchy, so the same sizes)
  } else {
    C = std::make_shared<Cycle<T>>();
    C->levels.resize(levels_.size());
    for (size_t l = 0; l < levels_.size(); ++l) {
      Work<T>& w = C->levels[l];
      const index n = levels_[l].A.size();
      const bool crosses = grids_->crosses_to_host(int(l));
      if (crosses) {  // (where the finer level runs: the device)
        w.x.resize(n);
        w.b.resize(n);
      }
      const HostLaunches where(on_host(l));
      w.r.resize(n);
      if (crosses) {
        w.host_x.resize(n);
        w.host_b.resize(n);
        w.xp = w.host_x.data();
        w.bp = w.host_b.data();
      } else if (l > 0 || !std::is_same<T, real>::value) {  // (a double level 0 solves in the
        w.x.resize(n);                                       // caller's arrays: apply sets xp, bp)
        w.b.resize(n);
        w.xp = w.x.data();
        w.bp = w.b.data();
      }
      if (l + 1 < levels_.size()) {
        const GridHierarchy::Link& k = grids_->to_coarse[l];
        if (k.fetch_fine) w.fine_rows.resize(k.fetch_fine->size());
        if (k.fetch_coarse) w.coarse_rows.resize(k.fetch_coarse->size());
      }
    }
  }
  refresh_work<T>();
}

template <class T>
void Multigrid::refresh_work() {
  std::vector<Field<T>>& D = held<T>().dinv;
  D.resize(levels_.size());
  for (size_t l = 0; l < levels_.size(); ++l) {
    const HostLaunches where(on_host(l));
    inverse_diagonal(levels_[l].A, D[l]);
  }
}

template <class T>
real Multigrid::estimate_lmax(int l, const ElasticityOperator& A, const Field<T>& dinv) const {
  const HostLaunches where(on_host(std::size_t(l)));
  const GridHierarchy::Level& h = grids_->levels[l];
  const index n = A.size();
  // the start vector by global dof index: runs of nx entries (one node row,
  // each from its own jump of the generator), made on the host's threads and
  // moved where the launches run
  const GridDims &box = h.slab.local, &G = h.grid;
  const index N = box.nodes(), row0 = h.slab.y_begin - h.slab.lo, ny = box.ny(), nz = box.nz();
  Field<T> r;
  {
    HostLaunches host;
    r = Field<T>(std::size_t(n));
    T* start = r.data();
    for_each_host_block("random start vector", 3 * nz * ny, double(n) * Cost{8, 4}, [=, &G, &box](index row) {
      const index c = row / (nz * ny), iz = (row / ny) % nz, j = row % ny;
      const index k0 = c * G.nodes() + G.node(0, row0 + j, iz);
      std::uint64_t s = Lcg::jump(12345, std::uint64_t(k0) + 1);
      T* out = start + c * N + box.node(0, j, iz);
      for (index ix = 0; ix < box.nx(); ++ix, s = Lcg::a * s + Lcg::c) out[ix] = T(Lcg::value(s));
    });
    r.move_to(host.space_before());
  }
  zero_constrained(box, A.faces(), r.data());
  A.zero_ghosts(r.data());
  // in the smoother's precision
  return lanczos_lmax<T>(
      n,
      [&](T* p, T* q) {
        A.update_ghosts(p);
        A.apply(p, q);
      },
      dinv, std::move(r), h.distributed ? grids_->comm : nullptr);
}

void Multigrid::factor_coarse() {
  // rank 0 factorises and solves the coarsest level (vcycle): K once, with
  // the dofs where a bottom block lands (set_bottom_block: the bottom
  // plane's unconstrained nodes) ordered last (coarse_solver.hpp)
  const ElasticityOperator& C = levels_.back().A;
  const index n = C.size();
  cb_.resize(n);
  cx_.resize(n);
  if (comm().rank() != 0) return;
  TRESCA_ASSERT(C.bottom_block().empty());
  coarse_.factor(assemble_stiffness(C), bottom_block_dofs(C.grid(), C.faces()));
}

void Multigrid::set_bottom_block(const std::vector<real>& B) {
  const GridDims& g0 = grids_->levels[0].grid;
  if (!B.empty() && index(B.size()) != 4 * g0.nx() * g0.ny())
    throw std::invalid_argument("multigrid: bottom block has " + std::to_string(B.size()) + " entries, expected 4 x " +
                                std::to_string(g0.nx() * g0.ny()));
  std::vector<real> Bl = B;  // this level's, whole plane
  for (size_t l = 0; l < levels_.size(); ++l) {
    const ElasticityOperator& A = levels_[l].A;
    zero_constrained_bottom_block(grids_->levels[l].grid, A.global_faces(), Bl);
    {
      const HostLaunches where(on_host(l));
      levels_[l].A.set_bottom_block(Bl);
    }
    if (l + 1 == levels_.size() || Bl.empty()) continue;
    Bl = project_bottom_block(grids_->to_coarse[l].whole, Bl);  // P^T B
  }
  if (comm().rank() == 0) {
    const ElasticityOperator& C = levels_.back().A;
    coarse_.update(assemble_bottom_block(C.grid(), C.bottom_block().to_vector()));
  }
  if (opt_.precision == Precision::single_precision)
    refresh_work<float>();
  else
    refresh_work<double>();
}

template <class T>
void Multigrid::residual(int l, const T* b, T* x, T* r) const {
  const ElasticityOperator& A = levels_[l].A;
  A.update_ghosts(x);
  A.residual(b, x, r);
}

template <class T>
void Multigrid::smooth(int l, bool zero_guess, const T* in) const {
  Work<T>& w = work<T>()[l];
  const T* dinv_l = held<T>().dinv[l].data();
  ScopedTimer t(Kernel::smoother);
  const ElasticityOperator& A = levels_[l].A;
  chebyshev_smooth<T>(
      A.size(), levels_[l].lmax, opt_.range, opt_.degree, zero_guess, dinv_l, w.bp, w.xp, w.r.data(),
      [&](T* x, T* r) { residual<T>(l, w.bp, x, r); },
      [&](T* x, T* y, T s, T t, bool from_zero) {
        A.update_ghosts(x);
        A.chebyshev_step(w.bp, x, y, dinv_l, s, t, from_zero);
      },
      in);
}

template <class T>
void Multigrid::restrict_residual(int l) const {
  // b_c = P^T r (the fine rows other ranks own fetched first)
  Work<T>& w = work<T>()[l];
  Work<T>& cw = work<T>()[l + 1];
  const GridHierarchy::Link& k = grids_->to_coarse[l];
  const ElasticityOperator& C = levels_[l + 1].A;
  ScopedTimer t(Kernel::restrict_, double(w.r.size()) * in_precision<T>(kRestrictCost));
  const T* fine = w.r.data();
  if (k.fetch_fine) {
    k.fetch_fine->fetch<T>(w.r.data(), w.fine_rows.data());
    fine = w.fine_rows.data();
  }
  if (grids_->agglomerated(l + 1) && comm().rank() != 0) return;
  TRESCA_ASSERT(k.restrict_t.coarse.nodes() == C.grid().nodes() && k.restrict_t.coarse.ey == C.grid().ey);
  restrict_to_coarse<T>(k.restrict_t, 3, fine, cw.b.data(), C.faces());  // zero on C's constrained faces
  C.zero_ghosts(cw.b.data());
}

template <class T>
T* Multigrid::prolongate_correction(int l) const {
  // x + P x_c (the coarse rows other ranks own fetched first), written where
  // the post-smoother's steps all fuse (smoothing.hpp: x itself or r); the
  // correction vanishes on constrained faces (they are interpolated from
  // constrained coarse nodes only), the mask makes it exact
  Work<T>& w = work<T>()[l];
  Work<T>& cw = work<T>()[l + 1];
  const GridHierarchy::Link& k = grids_->to_coarse[l];
  const ElasticityOperator& A = levels_[l].A;
  ScopedTimer t(Kernel::prolongate, double(w.r.size()) * in_precision<T>(kProlongateCost));
  const T* coarse = cw.x.data();
  if (k.fetch_coarse) {
    k.fetch_coarse->fetch<T>(cw.x.data(), w.coarse_rows.data());
    coarse = w.coarse_rows.data();
  }
  TRESCA_ASSERT(k.prolong_t.fine.nodes() == A.grid().nodes() && k.prolong_t.fine.ey == A.grid().ey);
  T* to = chebyshev_entry(opt_.degree, w.xp, w.r.data());
  prolongate<T>(k.prolong_t, 3, coarse, to, w.xp, A.faces());  // and zero on A's constrained faces
  return to;
}

template <class T>
void Multigrid::vcycle(int l) const {
  Work<T>& w = work<T>()[l];
  const index n = levels_[l].A.size();
  if (l + 1 == num_levels()) {  // on rank 0 (every rank if all levels are whole)
    // on the host: the right-hand side there and the solution back (a
    // copy each where the launches run on the device)
    ScopedTimer t(Kernel::coarse_solve);
    std::vector<T> v(n);
    space_copy(Space::host, v.data(), launch_space(), w.bp, n * sizeof(T));
    for (index i = 0; i < n; ++i) cb_[i] = real(v[i]);
    coarse_.solve(cb_, cx_);
    for (index i = 0; i < n; ++i) v[i] = T(cx_[i]);
    space_copy(launch_space(), w.xp, Space::host, v.data(), n * sizeof(T));
    return;
  }
  smooth<T>(l, true);
  residual<T>(l, w.bp, w.xp, w.r.data());
  restrict_residual<T>(l);
  vcycle_where_held<T>(l + 1);
  smooth<T>(l, false, prolongate_correction<T>(l));
}

template <class T>
void Multigrid::vcycle_where_held(int l) const {
  if (grids_->crosses_to_host(l)) {  // (a device run: one rank)
    ScopedTimer t(Kernel::host_levels);
    Work<T>& w = work<T>()[l];
    const std::size_t bytes = std::size_t(levels_[l].A.size()) * sizeof(T);
    space_copy(Space::host, w.host_b.data(), grids_->space, w.b.data(), bytes);
    {
      const HostLaunches host;
      vcycle<T>(l);
    }
    space_copy(grids_->space, w.x.data(), Space::host, w.host_x.data(), bytes);
    return;
  }
  if (!grids_->agglomerated(l)) {
    vcycle<T>(l);
    return;
  }
  // this level and the coarser ones on rank 0 alone; their correction to every rank
  if (comm().rank() == 0) vcycle<T>(l);
  comm().broadcast(work<T>()[l].xp, int(levels_[l].A.size()));
}

namespace {
// marks a V-cycle's work vectors in use for its span; one V-cycle inside
// another in the same vectors (multigrids that share them) is a defect
class InUse {
 public:
  template <class C>
  explicit InUse(C& c) : busy_(c.busy) {
    if (busy_) throw std::logic_error("multigrid: a V-cycle inside another one that shares its work vectors");
    busy_ = true;
  }
  ~InUse() { busy_ = false; }
  InUse(const InUse&) = delete;
  InUse& operator=(const InUse&) = delete;

 private:
  bool& busy_;
};
}  // namespace

void Multigrid::check_launch_space() const {
  if (levels_[0].A.stencil().groups.space() != launch_space())
    throw std::logic_error(std::string("multigrid: built with launches on the ") +
                           to_string(levels_[0].A.stencil().groups.space()) + ", applied with them on the " +
                           to_string(launch_space()));
}

void Multigrid::apply(const real* r, real* z) const {
  check_launch_space();
  const index n = size();
  if (opt_.precision == Precision::double_precision) {
    const InUse busy(*held<double>().cycle);
    Work<double>& w = work<double>()[0];
    w.bp = r;
    w.xp = z;
    vcycle_where_held<double>(0);
  } else {
    const InUse busy(*held<float>().cycle);
    Work<float>& w = work<float>()[0];
    w.bp = w.b.data();
    w.xp = w.x.data();
    convert<float>(n, r, w.b.data());
    vcycle_where_held<float>(0);
    convert<double>(n, w.x.data(), z);
  }
  levels_[0].A.zero_ghosts(z);
}

void Multigrid::apply_in_float(const float* r, float* z) const {
  if (!works_in_float()) throw std::logic_error("multigrid: apply_in_float on a V-cycle in double precision");
  check_launch_space();
  const InUse busy(*held<float>().cycle);
  Work<float>& w = work<float>()[0];
  w.bp = r;
  w.xp = z;
  vcycle_where_held<float>(0);
  levels_[0].A.zero_ghosts(z);
}

template <class T>
void Multigrid::vcycle_at(const Field<index>& at, const real* r, real* z) const {
  const InUse busy(*held<T>().cycle);
  Work<T>& w = work<T>()[0];
  const index n = size(), m = index(at.size());
  if (index(w.x.size()) != n) {  // (a double level 0 otherwise solves in the caller's arrays)
    w.x.resize(n);
    w.b.resize(n);
  }
  w.xp = w.x.data();
  w.bp = w.b.data();
  fill<T>(n, 0, w.b.data());
  scatter_to(m, at.data(), r, w.b.data());
  vcycle_where_held<T>(0);
  gather_from(m, at.data(), w.x.data(), z);
}

void Multigrid::apply_at(const Field<index>& at, const real* r, real* z) const {
  check_launch_space();
  if (!at.empty() && at.space() != launch_space())
    throw std::logic_error(std::string("multigrid: apply_at's entries on the ") + to_string(at.space()) +
                           ", the launches on the " + to_string(launch_space()));
  if (opt_.precision == Precision::double_precision)
    vcycle_at<double>(at, r, z);
  else
    vcycle_at<float>(at, r, z);
}

double Multigrid::cycle_work() const {
  double w = 0;
  for (size_t l = 0; l + 1 < levels_.size(); ++l) w += double(grids_->levels[l].grid.nodes());
  return 2.0 * opt_.degree * w / double(grids_->levels[0].grid.nodes());
}

std::string Multigrid::describe() const {
  std::ostringstream os;
  os << levels_.size() << " levels:";
  bool host = false;
  for (const GridHierarchy::Level& h : grids_->levels) {
    os << " " << h.grid.ex << "x" << h.grid.ey << "x" << h.grid.ez << (h.distributed ? "(d)" : "")
       << (h.on_host ? "(h)" : "");
    host = host || h.on_host;
  }
  os << " (" << to_string(opt_.precision) << " precision";
  if (host) os << "; (h): on the host, the finer ones on the device";
  if (comm().distributed() && grids_->distributed_levels() > 0)
    os << "; (d): split over " << comm().size() << " ranks, the others agglomerated on rank 0";
  else if (comm().distributed())
    os << "; every level on rank 0";
  os << ")";
  return os.str();
}

}  // namespace tresca
