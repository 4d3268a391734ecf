// Assembled sparse stiffness (Eigen), built element by element from Ke with
// the same constraint convention as the matrix-free operator (constrained
// rows/columns replaced by identity) plus the optional bottom-face blocks.
// Used for the coarsest multigrid level and as an independent test oracle.
#pragma once
#include <Eigen/SparseCore>

#include "core/fem/elasticity_operator.hpp"

namespace tresca {

using SparseMatrix = Eigen::SparseMatrix<real, Eigen::ColMajor, index>;

SparseMatrix assemble(const ElasticityOperator& op);

}  // namespace tresca
