// Nested iteration (coarse-to-fine Newton, issue 9 item 2): the contact
// problem is solved on a coarser mesh first and its contact state carried to
// the finer mesh as the Newton initial iterate there. The semismooth* Newton
// method is mesh independent, so the fine mesh is left with the few steps
// that resolve what the coarse mesh could not.
//
// Coarse mesh: ceil(e/2) elements per axis, same box and loads. The contact
// law is carried as densities, since phi_i and lambda_i are nodal forces:
//   phi:    coarse phi_j = (phi_i / A_i) * A_j, i the fine node nearest to j
//   gap:    coarse g_j = g_i (a length), i as above
//   u:      bilinear interpolation on the contact face (u = 0 on x = 0)
//   lambda: the pressure lambda/A, bilinearly interpolated, times A_i
// with A_i the node's share of the contact face (hx hy, halved on each edge).
#pragma once
#include <vector>

#include "core/contact/semismooth.hpp"
#include "core/fem/problem.hpp"

namespace tresca {

// ceil(e/2) elements per axis (level −1: explicit dims)
ProblemSpec coarser_spec(const ProblemSpec& s);

// whether nested iteration goes one mesh further down from s: the coarser
// mesh still has at least min_contact_nodes contact nodes and 2 elements
// along x (y and z may be one element thick: on a bar or a plate the coarse
// solve places the front of separation that the fine Newton steps would
// otherwise move a node or two a step, RESULTS.md §0zd)
bool has_coarser(const ProblemSpec& s, index min_contact_nodes);

// the contact law of the fine problem on the coarse one (densities, above)
ContactConditions coarse_conditions(const GridDims& fine, const ContactConditions& f, const GridDims& coarse);

// (u, lambda) of the coarse contact face interpolated to the fine one
void prolongate_contact(const GridDims& coarse, const std::vector<real>& uc, const std::vector<real>& lc,
                        const GridDims& fine, std::vector<real>& uf, std::vector<real>& lf);

// A_i of contact node c: its share of the contact face
real contact_area(const GridDims& g, index c);

}  // namespace tresca
