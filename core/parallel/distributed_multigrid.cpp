#include "core/parallel/distributed_multigrid.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "kernels/boundary_block.hpp"
#include "kernels/transfer.hpp"
#include "core/solvers/smoothing.hpp"
#include "kernels/vector_ops.hpp"
#include "core/util/profile.hpp"

namespace tresca {

// The V-cycle's vectors of one level in precision T.
template <class T>
struct DistributedMultigrid::Work {
  ElasticityStencilT<T> k;  // replicated levels: the whole grid's stencil
  std::vector<T> dinv;      // 1 / diag, 0 on ghost rows
  std::vector<T> B;         // bottom block of this level's rows (empty: none; 0 on ghost rows)
  mutable std::vector<T> x, b, r, d, fine_rows, coarse_rows;
  mutable T* xp = nullptr;  // iterate and right-hand side in use
  mutable const T* bp = nullptr;
};

// One level: distributed (slab, A with ghost exchange) or replicated (the
// whole grid's operator on every rank).
struct DistributedMultigrid::Level {
  GridDims g;
  bool distributed = false;
  Slab slab;                                  // distributed: this rank's; replicated: the whole grid
  std::unique_ptr<DistributedElasticity> Ad;  // distributed
  ElasticityOperator Ar;                      // replicated
  std::vector<real> dinv;  // double, for the Lanczos estimate
  std::vector<real> B;     // distributed levels: the bottom block of the local rows (ghost rows 0)
  Work<real> wd;
  Work<float> ws;
  real lmax = 0;
  index n = 0;  // local vector size
  // to the next coarser level
  std::unique_ptr<RowFetch> fetch_fine;    // the fine rows (of r here) the coarse rows restrict from
  std::unique_ptr<RowFetch> fetch_coarse;  // the coarse rows (of x there) this level interpolates from
  Transfer restrict_t, prolong_t;
  template <class T>
  const Work<T>& work() const {
    if constexpr (std::is_same<T, float>::value) return ws; else return wd;
  }
  template <class T>
  Work<T>& work() {
    if constexpr (std::is_same<T, float>::value) return ws; else return wd;
  }
  const LinearOperator& A() const { return distributed ? static_cast<const LinearOperator&>(*Ad) : Ar; }
};

namespace {

// deterministic value in [-0.5, 0.5] of a global dof index (splitmix64)
real hashed(std::uint64_t i) {
  std::uint64_t z = i + 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  z ^= z >> 31;
  return real(z >> 11) / real(1ULL << 53) - 0.5;
}

// local rows [first, last) of slab s as global rows
void row_range(const Slab& s, index& first, index& last) {
  first = s.y_begin - s.lo;
  last = s.y_end + s.hi;
}

}  // namespace

bool worth_distributing(const GridDims& g, const Comm& comm, index min_nodes_per_rank) {
  const int P = comm.size();
  return P > 1 && g.ny() >= 2 * P && g.nodes() / P >= min_nodes_per_rank;
}

DistributedMultigrid::DistributedMultigrid(const GridDims& fine, unsigned faces, real E, real nu, const MGOptions& opt,
                                           const Comm& comm, index min_nodes_per_rank, const DistributedMultigrid* like)
    : opt_(opt), comm_(comm), faces_(faces), grids_(GridHierarchy::build(fine, opt.coarse_nodes)) {
  const int P = comm.size();
  bool replicated = P == 1;
  for (const GridDims& g : grids_->grids) {
    auto lv = std::make_unique<Level>();
    lv->g = g;
    const bool coarsest = levels_.size() + 1 == grids_->grids.size();  // solved by a factorisation on each rank
    replicated = replicated || coarsest || !worth_distributing(g, comm, min_nodes_per_rank);
    lv->distributed = !replicated;
    if (lv->distributed) {
      lv->slab = make_slab(g, comm.rank(), P);
      lv->Ad = std::make_unique<DistributedElasticity>(lv->slab, faces, E, nu, comm);
      lv->n = lv->Ad->size();
    } else {
      lv->slab = make_slab(g, 0, 1);
      lv->Ar = ElasticityOperator(g, faces, E, nu);
      lv->n = lv->Ar.size();
    }
    levels_.push_back(std::move(lv));
  }
  if (!levels_[0]->distributed) op0_ = levels_[0]->Ar;  // K without the bottom block set later
  refresh_diagonals();
  if (like && (like->levels_.size() != levels_.size() || &like->comm_ != &comm_))
    throw std::invalid_argument("distributed multigrid: spectral bounds can only be shared on the same hierarchy");
  // transfers
  for (size_t l = 0; l + 1 < levels_.size(); ++l) {
    Level &f = *levels_[l], &c = *levels_[l + 1];
    const Transfer& T = grids_->to_coarse[l];
    const Interp1D& Y = T.axis[1];
    index f0, f1, c0, c1;
    row_range(f.slab, f0, f1);
    row_range(c.slab, c0, c1);
    if (!f.distributed) {  // both replicated
      f.restrict_t = f.prolong_t = T;
      continue;
    }
    if (!c.distributed) f.prolong_t = slice_rows(T, f0, f1, 0, c.g.ny());  // the coarse vector is whole here
    // restriction onto the coarse local rows [c0, c1): the fine rows of their
    // lists (onto a replicated level: all of them, on rank 0 alone)
    index a = f.g.ny(), b = 0;
    for (index j = c0; j < c1; ++j)
      for (index k = Y.tstart[j]; k < Y.tstart[j + 1]; ++k) a = std::min(a, Y.tf[k]), b = std::max(b, Y.tf[k] + 1);
    if (b - a < 2) b = std::min(f.g.ny(), a + 2), a = b - 2;
    if (!c.distributed && comm.rank() != 0) a = b = 0;
    f.fetch_fine = std::make_unique<RowFetch>(f.slab, a, b, comm);
    if (a == b) continue;  // (prolong_t below: the coarse vector is whole on every rank)
    f.restrict_t = slice_rows(T, a, b, c0, c1);
    // prolongation onto the fine local rows [f0, f1): the coarse rows they interpolate from
    index ca = c.g.ny(), cb = 0;
    for (index i = f0; i < f1; ++i) ca = std::min(ca, Y.j0[i]), cb = std::max(cb, Y.j0[i] + 2);
    cb = std::min(cb, c.g.ny());
    if (cb - ca < 2) ca = cb - 2;
    if (c.distributed) {
      f.fetch_coarse = std::make_unique<RowFetch>(c.slab, ca, cb, comm);
      f.prolong_t = slice_rows(T, f0, f1, ca, cb);
    }
  }
  for (size_t l = 0; l + 1 < levels_.size(); ++l) {
    if (like)
      levels_[l]->lmax = like->levels_[l]->lmax;
    else
      estimate_lmax(*levels_[l]);
  }
  factor_coarse();
  if (opt_.precision == Precision::single_precision)
    build_work<float>();
  else
    build_work<real>();
}

DistributedMultigrid::~DistributedMultigrid() = default;

void DistributedMultigrid::factor_coarse() {
  // rank 0 alone factorises and solves the coarsest level (vcycle)
  const index n = levels_.back()->n;
  cb_.resize(n);
  cx_.resize(n);
  if (comm_.rank() != 0) return;
  SparseMatrix A = assemble(levels_.back()->Ar);
  coarse_.compute(A);
  if (coarse_.info() != Eigen::Success) throw std::runtime_error("distributed multigrid: coarse factorisation failed");
}

void DistributedMultigrid::refresh_diagonals() {
  for (auto& lv : levels_) {
    if (lv->distributed) {
      lv->dinv.resize(lv->n);
      lv->Ad->diagonal(lv->dinv.data());
      if (!lv->B.empty()) {
        const GridDims& g = lv->slab.local;
        const index M = g.nx() * g.ny(), N = g.nodes();
        for (index m = 0; m < M; ++m) {
          lv->dinv[m] += lv->B[m];
          lv->dinv[N + m] += lv->B[2 * M + m];
          lv->dinv[2 * N + m] += lv->B[3 * M + m];
        }
        lv->Ad->zero_ghosts(lv->dinv.data());
      }
    } else {
      lv->dinv = lv->Ar.diagonal();
    }
    for (real& v : lv->dinv) v = v != 0 ? 1 / v : 0;  // ghost rows: 0
  }
}

void DistributedMultigrid::set_bottom_block(const std::vector<real>& B) {
  const GridDims& g0 = levels_[0]->g;
  if (!B.empty() && index(B.size()) != 4 * g0.nx() * g0.ny())
    throw std::invalid_argument("distributed multigrid: bottom block has " + std::to_string(B.size()) +
                                " entries, expected 4 x " + std::to_string(g0.nx() * g0.ny()));
  std::vector<real> Bl = B;  // this level's, whole plane
  for (size_t l = 0; l < levels_.size(); ++l) {
    Level& lv = *levels_[l];
    const GridDims& g = lv.g;
    const index M = g.nx() * g.ny();
    if (!Bl.empty())  // zero on constrained nodes, as ElasticityOperator::set_bottom_block
      for (index iy = 0; iy < g.ny(); ++iy)
        for (index ix = 0; ix < g.nx(); ++ix)
          if (node_constrained(g, faces_, ix, iy, 0))
            for (int f = 0; f < 4; ++f) Bl[f * M + ix + g.nx() * iy] = 0;
    if (lv.distributed) {
      lv.B.clear();
      if (!Bl.empty()) {
        const GridDims& box = lv.slab.local;
        const index Ml = box.nx() * box.ny(), row0 = lv.slab.y_begin - lv.slab.lo;
        lv.B.assign(4 * Ml, 0.0);
        for (int f = 0; f < 4; ++f)  // owned rows only: ghost rows stay 0
          std::copy_n(Bl.data() + f * M + g.nx() * lv.slab.y_begin, g.nx() * lv.slab.owned_rows(),
                      lv.B.data() + f * Ml + box.nx() * (lv.slab.y_begin - row0));
      }
    } else {
      lv.Ar.set_bottom_block(Bl);
    }
    if (l + 1 == levels_.size()) break;
    if (Bl.empty()) continue;
    std::vector<real> Bc = project_bottom_block(grids_->to_coarse[l], Bl);  // P^T B (multigrid.cpp)
    Bl = std::move(Bc);
  }
  refresh_diagonals();
  factor_coarse();
  if (opt_.precision == Precision::single_precision)
    refresh_work<float>();
  else
    refresh_work<real>();
}

template <class T>
void DistributedMultigrid::refresh_work() {
  for (auto& lv : levels_) {
    Work<T>& w = lv->work<T>();
    w.dinv.assign(lv->dinv.begin(), lv->dinv.end());
    const std::vector<real>& B = lv->distributed ? lv->B : lv->Ar.bottom_block();
    w.B.assign(B.begin(), B.end());
  }
}

template <class T>
void DistributedMultigrid::build_work() {
  for (auto& lv : levels_) {
    Work<T>& w = lv->work<T>();
    if (!lv->distributed) w.k = stencil_in_precision<T>(lv->Ar.stencil());
    for (auto* v : {&w.x, &w.b, &w.r, &w.d}) v->resize(lv->n);
    if (lv->fetch_fine) w.fine_rows.resize(lv->fetch_fine->size());
    if (lv->fetch_coarse) w.coarse_rows.resize(lv->fetch_coarse->size());
    w.xp = w.x.data();
    w.bp = w.b.data();
  }
  refresh_work<T>();
}

index DistributedMultigrid::size() const { return levels_[0]->n; }
const LinearOperator& DistributedMultigrid::op() const {
  return levels_[0]->distributed ? static_cast<const LinearOperator&>(*levels_[0]->Ad) : op0_;
}
bool DistributedMultigrid::fine_distributed() const { return levels_[0]->distributed; }
const Slab& DistributedMultigrid::fine_slab() const { return levels_[0]->slab; }
real DistributedMultigrid::lmax(int level) const { return levels_[level]->lmax; }
int DistributedMultigrid::distributed_levels() const {
  int k = 0;
  for (const auto& lv : levels_) k += lv->distributed ? 1 : 0;
  return k;
}

void DistributedMultigrid::estimate_lmax(Level& lv) {
  // multigrid.cpp's estimate; the start vector hashed from the global dof
  // index (the same on any rank count), dots over all ranks if distributed
  const index n = lv.n;
  std::vector<real> r(n);
  const GridDims& box = lv.slab.local;
  const index N = box.nodes(), G = lv.g.nodes(), row0 = lv.slab.y_begin - lv.slab.lo;
  for (int c = 0; c < 3; ++c)
    for (index iz = 0; iz < box.nz(); ++iz)
      for (index j = 0; j < box.ny(); ++j)
        for (index ix = 0; ix < box.nx(); ++ix)
          r[c * N + box.node(ix, j, iz)] = hashed(std::uint64_t(c * G + lv.g.node(ix, row0 + j, iz)));
  zero_constrained(box, lv.slab.local_faces(faces_), r.data());
  if (lv.distributed) lv.Ad->zero_ghosts(r.data());
  std::function<real(real)> reduce;
  if (lv.distributed) reduce = [this](real s) { return comm_.sum(s); };
  lv.lmax = lanczos_lmax(n, [&](const real* p, real* q) { lv.A().apply(p, q); }, lv.dinv, std::move(r), reduce);
}

template <class T>
void DistributedMultigrid::residual(const Level& lv, const T* b, const T* x, T* r) const {
  const Work<T>& w = lv.work<T>();
  if (lv.distributed) {
    lv.Ad->residual(b, x, r);
  } else {
    ScopedTimer t(Kernel::apply, double(lv.g.nodes()) * in_precision<T>(kResidualCost));
    elasticity_apply<T>(w.k, x, r, 0, lv.g.nz(), b);
  }
  if (!w.B.empty()) {  // B is 0 on ghost rows, which stay 0
    const GridDims& g = lv.slab.local;
    ScopedTimer t(Kernel::apply_boundary, double(g.nx() * g.ny()) * in_precision<T>(kBottomBlockCost));
    bottom_block_apply<T>(g, T(-1), w.B.data(), x, r);
  }
}

template <class T>
void DistributedMultigrid::smooth(int l, bool zero_guess) const {
  const Level& lv = *levels_[l];
  const Work<T>& w = lv.work<T>();
  ScopedTimer t(Kernel::smoother);
  chebyshev_smooth<T>(lv.n, lv.lmax, opt_.range, opt_.degree, zero_guess, w.dinv.data(), w.bp, w.xp, w.r.data(),
                      w.d.data(), [&](const T* x, T* r) { residual<T>(lv, w.bp, x, r); });
}

template <class T>
void DistributedMultigrid::vcycle(int l) const {
  const Level& lv = *levels_[l];
  const Work<T>& w = lv.work<T>();
  if (l + 1 == int(levels_.size())) {
    // (replicated levels run on rank 0 alone when there are several ranks)
    ScopedTimer t(Kernel::coarse_solve);
    for (index i = 0; i < lv.n; ++i) cb_[i] = real(w.bp[i]);
    cx_ = coarse_.solve(cb_);
    for (index i = 0; i < lv.n; ++i) w.xp[i] = T(cx_[i]);
    return;
  }
  const Level& c = *levels_[l + 1];
  const Work<T>& cw = c.work<T>();
  smooth<T>(l, true);
  residual<T>(lv, w.bp, w.xp, w.r.data());
  {
    ScopedTimer t(Kernel::restrict_, double(lv.n) * in_precision<T>(kRestrictCost));
    const T* fine = w.r.data();
    if (lv.fetch_fine) {
      lv.fetch_fine->fetch<T>(w.r.data(), w.fine_rows.data());
      fine = w.fine_rows.data();
    }
    if (!agglomerated(l + 1) || comm_.rank() == 0) {
      restrict_to_coarse<T>(lv.restrict_t, 3, fine, cw.b.data());
      zero_constrained<T>(c.slab.local, c.slab.local_faces(faces_), cw.b.data());
      if (c.distributed) c.Ad->zero_ghosts(cw.b.data());
    }
  }
  if (agglomerated(l + 1)) {
    // the coarse levels on rank 0 alone; their correction to every rank
    if (comm_.rank() == 0) vcycle<T>(l + 1);
    comm_.broadcast(cw.x.data(), int(c.n));
  } else {
    vcycle<T>(l + 1);
  }
  {
    ScopedTimer t(Kernel::prolongate, double(lv.n) * in_precision<T>(kProlongateCost));
    const T* coarse = cw.x.data();
    if (lv.fetch_coarse) {
      lv.fetch_coarse->fetch<T>(cw.x.data(), w.coarse_rows.data());
      coarse = w.coarse_rows.data();
    }
    prolongate<T>(lv.prolong_t, 3, coarse, w.xp, true);
    zero_constrained<T>(lv.slab.local, lv.slab.local_faces(faces_), w.xp);
  }
  smooth<T>(l, false);
}

void DistributedMultigrid::apply(const real* r, real* z) const {
  const Level& f = *levels_[0];
  // all levels replicated on several ranks: rank 0 alone, the answer to all
  const bool alone = agglomerated(0);
  if (opt_.precision == Precision::double_precision) {
    f.wd.bp = r;
    f.wd.xp = z;
    if (!alone || comm_.rank() == 0) vcycle<real>(0);
    f.wd.bp = f.wd.b.data();
    f.wd.xp = f.wd.x.data();
  } else {
    convert<float>(f.n, r, f.ws.b.data());
    if (!alone || comm_.rank() == 0) vcycle<float>(0);
    convert<double>(f.n, f.ws.x.data(), z);
  }
  if (alone) comm_.broadcast(z, int(f.n));
  if (f.distributed) f.Ad->zero_ghosts(z);
}

bool DistributedMultigrid::agglomerated(int l) const {
  return comm_.distributed() && !levels_[l]->distributed && (l == 0 || levels_[l - 1]->distributed);
}

double DistributedMultigrid::cycle_work() const {
  double w = 0;
  for (size_t l = 0; l + 1 < levels_.size(); ++l) w += double(levels_[l]->g.nodes());
  return 2.0 * opt_.degree * w / double(levels_[0]->g.nodes());
}

std::string DistributedMultigrid::describe() const {
  std::ostringstream os;
  os << levels_.size() << " levels:";
  for (const auto& lv : levels_) os << " " << lv->g.ex << "x" << lv->g.ey << "x" << lv->g.ez << (lv->distributed ? "(d)" : "");
  os << " (" << to_string(opt_.precision) << " precision; (d): distributed over " << comm_.size()
     << " ranks, the others agglomerated on rank 0)";
  return os.str();
}

}  // namespace tresca
