// The contact Steklov–Poincaré operator and condensed load (method.md §2),
// applied matrix-free, never formed:
//
//   S v = K_cc v − K_ci K_ii^{-1} K_ic v = (K E v)_c ,
//   b̃  = l_c − K_ci K_ii^{-1} l_i ,
//   u   = E u_c + K_ii^{-1} l_i                  (recovery of the body)
//
// where E v = w + z is the discrete harmonic extension: w = v on the contact
// face (zero elsewhere) and K_ii z = −K_ic v. K has u = 0 on x = 0; K_ii also
// on the contact face z = z0. K_ii is solved by CG preconditioned with one
// geometric-multigrid V-cycle (multigrid.hpp). Because w lives on the bottom
// plane, K_ic v needs K only on plane iz = 1 and (K E v)_c only on iz = 0.
//
// DATA LAYOUT: contact vectors are SoA of 3 blocks of p values
// [u_x(0..p-1) | u_y | u_z], contact node c as in problem.hpp. Every vector
// argument, contact or 3D, lives where the launches run (kernels/launch.hpp:
// device memory while the launches are on the device); the exceptions
// return std::vector (host values: local_part, whole, contact_diagonal).
// Cost per apply: one inner MG-CG solve (dominant) + 2 plane applies.
//
// Ranks: when the run has several MPI ranks and the grid is worth splitting
// (worth_distributing), the 3D vectors are y-slab local vectors (slab.hpp;
// full_size() entries), K and the K_ii multigrid are split, and so are the
// contact vectors: a rank's contact nodes are those of its rows, c in
// [first_contact_node(), + contact_nodes()), and its contact vectors hold
// just those (3 blocks of contact_nodes()). Sums and maxima over contact
// vectors go through sum() and max(); local_part and whole convert from and
// to vectors of every contact node. Otherwise every rank holds the whole
// problem (comm() is Comm::self()): one slab, the same code, no messages.
//
// State: the operator is immutable after construction. Every call takes the
// inner solve's relative tolerance and returns that solve's SolveStats (the
// caller counts its own work); the full-size work vectors are scratch only
// (one call at a time per object).
#pragma once
#include <vector>

#include <cstdint>
#include <memory>

#include "core/solvers/cg.hpp"
#include "core/multigrid/multigrid.hpp"
#include "core/fem/problem.hpp"
#include "core/parallel/comm.hpp"

namespace tresca {

class SteklovPoincare {
 public:
  SteklovPoincare(const Problem& P, const MGOptions& mg = {}, const Comm& comm = Comm::world());
  ~SteklovPoincare();
  index size() const { return 3 * p_; }  // this rank's contact dofs
  // this rank's contact nodes c in [first_contact_node(), + contact_nodes())
  index contact_nodes() const { return p_; }
  index first_contact_node() const { return c_begin_; }
  // sum and maximum over the ranks of a contact-vector quantity (identity on one rank)
  real sum(real local) const;
  real max(real local) const;
  // a vector of `blocks` blocks of every contact node -> this rank's part, and back
  std::vector<real> local_part(const std::vector<real>& whole, int blocks) const;
  std::vector<real> whole(const std::vector<real>& local, int blocks) const;
  std::vector<std::uint8_t> whole(const std::vector<std::uint8_t>& local) const;
  // entries of a 3D vector (extension, guess, interior): 3N, or 3 x the
  // rank's slab nodes when distributed
  index full_size() const { return K_.size(); }
  bool distributed() const { return K_.distributed(); }
  // this rank's slab of the grid (the whole grid when not split)
  const Slab& slab() const { return K_.slab(); }
  // the ghost rows of a 3D vector := the neighbours' values (nothing when not split)
  void exchange_ghosts(real* full) const { K_.update_ghosts(full); }
  // the ranks the vectors are split over (Comm::self() when not split)
  const Comm& comm() const { return comm_; }
  const MGOptions& mg_options() const { return mg_opt_; }
  // diag(K) at the contact nodes, 3 blocks of p (K clamped on x = 0 only)
  std::vector<real> contact_diagonal() const;
  // Sv = S v with the inner K_ii solve to relative tolerance rtol (of the
  // solve's right-hand side, so a good initial guess means fewer iterations,
  // not a looser answer); with `extension`, also E v there (3N SoA: v on the
  // contact face, the discrete harmonic extension inside, 0 on x = 0). guess
  // (3N, may be `extension` itself): initial guess of E v for the inner solve.
  SolveStats apply(const real* v, real* Sv, real rtol, real* extension = nullptr, const real* guess = nullptr) const;
  // r = S u − b̃ (3p) with one inner solve, K_ii y = l_i − K_ic u, to
  // relative tolerance rtol: the contact forces that hold the body at u on
  // the contact face. With `body`, also the body's displacement there (u on
  // the face, y inside: E u + K_ii^{-1} l_i). guess (may be `body`): initial
  // guess of the body, e.g. the last one moved by E Δu: the solve then only
  // corrects, and the residual is true to rtol whatever the guess.
  SolveStats residual(const real* u, real* r, real rtol, real* body = nullptr, const real* guess = nullptr) const;
  // b = b̃ = -residual(0) (3p) with the inner solve to relative tolerance rtol; with
  // `interior`, also K_ii^{-1} l_i there (3N SoA). The body's displacement
  // for contact values u_c is then E u_c + K_ii^{-1} l_i: recovery costs no
  // solve beyond the final check's S u_c.
  // guess (3N): initial guess of K_ii^{-1} l_i.
  SolveStats condensed_load(real rtol, Field<real>& b, Field<real>* interior = nullptr,
                            const real* guess = nullptr) const;
  // b ≈ b̃ without a solve: l_c − K_ci z for a given z ≈ K_ii^{-1} l_i (3N,
  // e.g. a coarser mesh's, prolongated; its constrained values are zeroed in
  // place). Plane-sized work: only z's plane next to the contact face
  // enters, so b's error is z's there (about 1 % from a coarser mesh's solve
  // at levels 9 to 12: perf/RESULTS.md §0zp).
  void condensed_load_from(real* interior, Field<real>& b) const;

  // the K_ii multigrid; its hierarchy() is shared with the Newton step's preconditioner
  const Multigrid& interior_multigrid() const { return *mg_; }
  // work of one apply in fine-grid matvec equivalents, given the inner CG
  // iterations it took: each iteration one K_ii apply and one V-cycle, plus
  // the two plane applies around the solve
  double apply_work(long long inner_iterations) const;
  const Problem& problem() const { return P_; }

  // where this rank's contact values lie in a full SoA grid vector: its 3p
  // contact dofs (component a of node c - first_contact_node() at a p + c)
  // are the entries contact_rows()[a p + c] (where the launches run)
  const Field<index>& contact_rows() const { return rows_; }

 private:
  // scatter contact values into / gather them from a full SoA grid vector
  void scatter(const real* vc, real* full) const;
  void gather(const real* full, real* vc) const;
  SolveStats solve_interior(const real* rhs, real* z, real rtol, const real* guess = nullptr) const;
  // out = (K x)_c for x = v on the contact face and z inside, where
  // K_ii z = −K_ic v, or with li (the interior load, 3D, overwritten)
  // K_ii z = l_i − K_ic v; x into `extension` if given
  SolveStats extend(const real* v, real* li, real* out, real rtol, real* extension, const real* guess) const;
  // out = (K x)_c, the contact rows of K x (x 3D, its ghost rows updated)
  void contact_rows_of_K(real* x, real* out) const;
  // plane iz of all 3 components of v := src's (or 0 if src is null)
  void set_plane(real* v, index iz, const real* src) const;
  // y = K x on planes [z_begin, z_end), x's ghost rows updated first
  void apply_planes(real* x, real* y, index z_begin, index z_end) const;
  const GridDims& box() const { return slab().local; }  // the grid of the 3D vectors

  const Problem& P_;
  index p_;
  const Comm& comm_;
  MGOptions mg_opt_;
  ElasticityOperator K_;           // faces x0
  std::unique_ptr<Multigrid> mg_;  // K_ii, faces x0 | z0
  index c_begin_ = 0, c_end_ = 0;  // this rank's contact nodes
  std::vector<int> counts_, displs_;           // every rank's contact nodes (whole())
  mutable CGWorkspace ws_;  // scratch
  Field<index> rows_;                         // contact_rows()
  Field<real> interior_load_, contact_load_;  // l_i (K_ii's rows: 3D) and l_c (3p), this rank's
  mutable Field<real> w_, t_, z_, load_;     // z_: extend()'s without an extension; load_: residual()'s right-hand side
};

}  // namespace tresca
