// Dense reference objects for the tests: the Schur complement S, condensed
// load b̃ and interior blocks computed directly from the assembled K with
// Eigen dense factorisations (method.md §2), independent of the matrix-free path.
#pragma once
#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <vector>

#include "core/fem/assembly.hpp"
#include "core/fem/problem.hpp"

namespace tresca {
// the largest eigenvalue of D^{-1} K (of D^{-1/2} K D^{-1/2}, K assembled
// element by element; its constrained rows are the identity's) by a dense
// symmetric eigensolver: the oracle of the smoother's spectral bounds
inline real jacobi_scaled_lmax(const ElasticityOperator& K) {
  const Eigen::MatrixXd A(assemble(K));
  const Eigen::VectorXd s = A.diagonal().cwiseInverse().cwiseSqrt();
  const Eigen::MatrixXd scaled = s.asDiagonal() * A * s.asDiagonal();
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
}

struct DenseSchur {
  Eigen::MatrixXd S;
  Eigen::VectorXd b;
  Eigen::MatrixXd Kii, Kic;
  Eigen::VectorXd li;
  std::vector<index> cdof, idof;
};

inline DenseSchur dense_schur(const Problem& P) {
  ElasticityOperator K(P.grid, P.dirichlet_faces, P.spec.E, P.spec.nu);
  const Eigen::MatrixXd Kd = Eigen::MatrixXd(assemble(K));
  const GridDims& g = P.grid;
  const index N = g.nodes(), p = P.contact_nodes();
  DenseSchur d;
  d.cdof.resize(3 * p);
  for (int a = 0; a < 3; ++a)
    for (index c = 0; c < p; ++c) d.cdof[a * p + c] = a * N + P.contact_grid_node(c);
  for (int a = 0; a < 3; ++a)
    for (index iz = 1; iz < g.nz(); ++iz)
      for (index iy = 0; iy < g.ny(); ++iy)
        for (index ix = 1; ix < g.nx(); ++ix) d.idof.push_back(a * N + g.node(ix, iy, iz));
  const index nc = index(d.cdof.size()), ni = index(d.idof.size());
  Eigen::MatrixXd Kcc(nc, nc), Kci(nc, ni);
  d.Kii.resize(ni, ni);
  for (index r = 0; r < nc; ++r) {
    for (index c = 0; c < nc; ++c) Kcc(r, c) = Kd(d.cdof[r], d.cdof[c]);
    for (index c = 0; c < ni; ++c) Kci(r, c) = Kd(d.cdof[r], d.idof[c]);
  }
  for (index r = 0; r < ni; ++r)
    for (index c = 0; c < ni; ++c) d.Kii(r, c) = Kd(d.idof[r], d.idof[c]);
  d.Kic = Kci.transpose();
  Eigen::VectorXd lc(nc);
  d.li.resize(ni);
  const Field<real> load = whole_load(P);
  for (index r = 0; r < nc; ++r) lc[r] = load[d.cdof[r]];
  for (index r = 0; r < ni; ++r) d.li[r] = load[d.idof[r]];
  Eigen::LDLT<Eigen::MatrixXd> f(d.Kii);
  d.S = Kcc - Kci * f.solve(d.Kic);
  d.b = lc - Kci * f.solve(d.li);
  return d;
}

}  // namespace tresca
