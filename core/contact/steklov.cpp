#include "core/contact/steklov.hpp"

#include <stdexcept>
#include <string>

#include "kernels/vector_ops.hpp"
#include "core/util/profile.hpp"

namespace tresca {

SteklovPoincare::SteklovPoincare(const Problem& P, const MGOptions& mg, const Comm& comm)
    : P_(P), p_(P.contact_nodes()), comm_(split_over(P.grid, comm)), mg_opt_(mg) {
  const auto grids = GridHierarchy::build(P.grid, mg.coarse_nodes, comm_);
  K_ = ElasticityOperator(grids->levels[0].slab, P.dirichlet_faces, P.spec.E, P.spec.nu);
  // (its smoother's bounds from K with the contact face free: they hold
  // for the Newton step's K + B too, which shares them)
  mg_ = std::make_unique<Multigrid>(grids, elasticity_on(P.interior_faces, P.spec.E, P.spec.nu), mg, nullptr,
                                    elasticity_on(P.dirichlet_faces, P.spec.E, P.spec.nu));
  // contact node c = (ix - 1) + ex iy: a rank's rows hold a contiguous range
  const index ex = P.grid.ex;
  c_begin_ = ex * slab().y_begin;
  c_end_ = ex * slab().y_end;
  p_ = c_end_ - c_begin_;  // contact vectors hold this rank's nodes
  counts_.resize(comm_.size());
  displs_.resize(comm_.size());
  for (int q = 0; q < comm_.size(); ++q) {
    const Slab s = make_slab(P.grid, q, comm_.size());
    counts_[q] = int(ex * s.owned_rows());
    displs_[q] = int(ex * s.y_begin);
  }
  const index n = full_size();
  // contact node c = c_begin_ + k is ix = 1 + c % ex, row c / ex - row0, iz = 0
  rows_ = Field<index>(std::size_t(3 * p_));
  {
    const index N = box().nodes(), nx = box().nx(), row0 = slab().y_begin - slab().lo, c0 = c_begin_, p = p_;
    index* rows = rows_.data();
    for_each_entry("contact rows", p, Cost{24, 0}, [=](index k) {
      const index c = c0 + k, node = 1 + c % ex + nx * (c / ex - row0);
      for (int a = 0; a < 3; ++a) rows[a * p + k] = a * N + node;
    });
  }
  // the load on this rank's rows (all of it on one rank): its contact part
  // and its interior part, made once where the launches run
  interior_load_ = load_on(P, slab());
  contact_load_ = Field<real>(3 * p_);
  gather(interior_load_.data(), contact_load_.data());
  zero_constrained(box(), mg_->op(0).faces(), interior_load_.data());
  K_.zero_ghosts(interior_load_.data());
  w_.assign(n, 0);
  t_.assign(n, 0);
}

SteklovPoincare::~SteklovPoincare() = default;

void SteklovPoincare::scatter(const real* vc, real* full) const { scatter_to(3 * p_, rows_.data(), vc, full); }

void SteklovPoincare::gather(const real* full, real* vc) const { gather_from(3 * p_, rows_.data(), full, vc); }

real SteklovPoincare::sum(real local) const { return comm_.sum(local); }
real SteklovPoincare::max(real local) const { return real(comm_.max(local)); }

std::vector<real> SteklovPoincare::local_part(const std::vector<real>& whole, int blocks) const {
  const index pg = P_.contact_nodes();
  if (index(whole.size()) != blocks * pg)
    throw std::invalid_argument("SteklovPoincare::local_part: " + std::to_string(whole.size()) + " values, expected " +
                                std::to_string(blocks * pg));
  std::vector<real> v(blocks * p_);
  for (int a = 0; a < blocks; ++a) std::copy_n(whole.data() + a * pg + c_begin_, p_, v.data() + a * p_);
  return v;
}

std::vector<real> SteklovPoincare::whole(const std::vector<real>& local, int blocks) const {
  if (!distributed() || local.empty()) return local;  // (empty: nothing to gather, e.g. a failed run's S u)
  if (index(local.size()) != blocks * p_)
    throw std::invalid_argument("SteklovPoincare::whole: " + std::to_string(local.size()) + " values, expected " +
                                std::to_string(blocks * p_));
  const index pg = P_.contact_nodes();
  std::vector<real> v(blocks * pg, 0.0);
  for (int a = 0; a < blocks; ++a) {
    std::copy_n(local.data() + a * p_, p_, v.data() + a * pg + c_begin_);
    comm_.allgather(v.data() + a * pg, counts_, displs_);
  }
  return v;
}

std::vector<std::uint8_t> SteklovPoincare::whole(const std::vector<std::uint8_t>& local) const {
  if (!distributed() || local.empty()) return local;
  const std::vector<real> w = whole(std::vector<real>(local.begin(), local.end()), 1);
  return std::vector<std::uint8_t>(w.begin(), w.end());
}

std::vector<real> SteklovPoincare::contact_diagonal() const {
  Field<real> dc(3 * p_);
  gather(K_.diagonal().data(), dc.data());
  return dc.to_vector();
}

void SteklovPoincare::apply_planes(real* x, real* y, index z_begin, index z_end) const {
  K_.update_ghosts(x);
  K_.apply_planes(x, y, z_begin, z_end);
}

SolveStats SteklovPoincare::solve_interior(const real* rhs, real* z, real rtol, const real* guess) const {
  ScopedTimer t(Kernel::inner_cg);
  CGOptions o;
  o.rtol = rtol;
  const ElasticityOperator& Kii = mg_->op(0);
  if (guess) {
    if (guess != z) copy(full_size(), guess, z);
    zero_constrained(box(), Kii.faces(), z);  // the guess of an extension carries v on plane 0
    o.zero_initial_guess = false;
  }
  o.max_iterations = 500;
  o.reduction = &comm_;
  return pcg(Kii, mg_.get(), rhs, z, o, ws_);
}

void SteklovPoincare::set_plane(real* v, index iz, const real* src) const {
  const GridDims& g = box();
  const index plane = g.nx() * g.ny();
  const ComponentRuns at{g.nodes(), iz * plane, plane};
  if (src)
    copy(at, src, v);
  else
    fill(at, 0, v);
}

SolveStats SteklovPoincare::apply(const real* v, real* Sv, real rtol, real* extension, const real* guess) const {
  return extend(v, nullptr, Sv, rtol, extension, guess);
}

SolveStats SteklovPoincare::residual(const real* u, real* r, real rtol, real* body, const real* guess) const {
  // the interior load is the solve's right-hand side besides -K_ic u (a
  // copy: extend adds that plane into it)
  load_.resize(full_size());
  copy(full_size(), interior_load_.data(), load_.data());
  const SolveStats st = extend(u, load_.data(), r, rtol, body, guess);
  axpy(3 * p_, -1, contact_load_.data(), r);
  return st;
}

SolveStats SteklovPoincare::extend(const real* v, real* li, real* out, real rtol, real* extension,
                                   const real* guess) const {
  // Invariants between calls: w_ is zero off the contact nodes, t_ is zero
  // off plane 1, so only plane-sized work surrounds the inner solve.
  const GridDims& g = box();
  const index N = g.nodes(), plane = g.nx() * g.ny();
  scatter(v, w_.data());
  // t = -K_ic v lives on plane 1 (w_ is zero on the x = 0 nodes, so are t's)
  apply_planes(w_.data(), t_.data(), 1, 2);
  const ComponentRuns plane1{N, plane, plane};
  scale(plane1, -1, t_.data());
  // right-hand side -K_ic v, or l_i - K_ic v in li itself
  if (li) axpy(plane1, 1, t_.data(), li);
  // z solved where u = w + z is wanted: in `extension` itself (from the
  // guess in place where that is the same array), or in z_, made when a
  // call first has no extension (the Newton steps' CG always gives one)
  if (!extension && index(z_.size()) != full_size()) z_.resize(full_size());
  real* z = extension ? extension : z_.data();
  const SolveStats st = solve_interior(li ? li : t_.data(), z, rtol, guess);
  // u = w + z: z vanishes on the constrained plane 0, where w lives
  set_plane(z, 0, w_.data());
  contact_rows_of_K(z, out);
  return st;
}

void SteklovPoincare::contact_rows_of_K(real* x, real* out) const {
  // (K x)_c on plane 0, then restore t_'s invariant
  apply_planes(x, t_.data(), 0, 1);
  gather(t_.data(), out);
  set_plane(t_.data(), 0, nullptr);
}

double SteklovPoincare::apply_work(long long inner_iterations) const {
  return double(inner_iterations) * (1 + mg_->cycle_work()) + 2.0 / double(P_.grid.nz());
}

SolveStats SteklovPoincare::condensed_load(real rtol, Field<real>& b, Field<real>* interior,
                                           const real* guess) const {
  // b̃ = -(S 0 - b̃)
  const Field<real> zero(3 * p_);
  b = Field<real>(3 * p_);
  if (interior) interior->resize(full_size());
  const SolveStats st = residual(zero.data(), b.data(), rtol, interior ? interior->data() : nullptr, guess);
  scale(3 * p_, -1, b.data());
  return st;
}

void SteklovPoincare::condensed_load_from(real* interior, Field<real>& b) const {
  if (index(b.size()) != 3 * p_) b = Field<real>(3 * p_);
  // z on the contact face is u = 0 (a constrained plane of K_ii)
  zero_constrained(box(), mg_->op(0).faces(), interior);
  // b̃ = −((K z)_c − l_c), as condensed_load's −residual(0)
  contact_rows_of_K(interior, b.data());
  axpy(3 * p_, -1, contact_load_.data(), b.data());
  scale(3 * p_, -1, b.data());
}

}  // namespace tresca
