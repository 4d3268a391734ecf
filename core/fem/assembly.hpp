// Assembled sparse stiffness (Eigen), summed from the element matrix Ke
// (each column from the elements around its node, in element order: the
// sums of an element-by-element assembly) with the same constraint
// convention as the matrix-free operator (constrained rows/columns replaced
// by identity), plus the optional bottom-face blocks.
// Used for the coarsest multigrid level and as an independent test oracle.
#pragma once
#include <Eigen/SparseCore>
#include <vector>

#include "core/fem/elasticity_operator.hpp"

namespace tresca {

using SparseMatrix = Eigen::SparseMatrix<real, Eigen::ColMajor, index>;

// K + B of op (its bottom block, if set)
SparseMatrix assemble(const ElasticityOperator& op);
// K alone
SparseMatrix assemble_stiffness(const ElasticityOperator& op);
// B alone, from its 4 fields over the bottom plane of g (bxx, bxy, byy, bzz;
// ElasticityOperator::set_bottom_block), as a 3N x 3N matrix; empty B: a zero one
SparseMatrix assemble_bottom_block(const GridDims& g, const std::vector<real>& B);
// the dofs such a B may touch where `faces` are constrained: those of the
// bottom plane's unconstrained nodes (component by component, in node order)
std::vector<index> bottom_block_dofs(const GridDims& g, unsigned faces);

}  // namespace tresca
