// The communication model of the domain-decomposed solver (issue 12, item
// 5): messages and bytes per rank for one apply, one V-cycle and one
// MG-preconditioned CG iteration, as functions of the mesh and the rank
// grid px x py (boxes in x and y; slabs are px = 1), and a time from an
// assumed network (latency alpha, bandwidth beta per rank).
//
// Per apply, an interior rank exchanges one ghost layer with its 4 face
// neighbours (a plane of ny/py x nz or nx/px x nz nodes) and 4 edge
// neighbours (a column of nz nodes: the 27-point stencil reaches across
// corners), 3 doubles per node. Slab ranks (px = 1) have 2 face neighbours.
// A V-cycle of Chebyshev degree d costs on each level 2d + 1 applies
// (smoother and residual) and one exchange before each of the restriction and
// the prolongation; levels with fewer than `agglomerate_nodes` nodes per
// rank are gathered onto one rank (two collectives of the level's vector per
// cycle, counted as P messages of its size / P). A CG iteration adds two
// allreduces of one double (log2 P latencies each).
#pragma once
#include <vector>

#include "kernels/grid.hpp"

namespace tresca {

struct CommVolume {
  double messages = 0, bytes = 0;  // point-to-point, sent per rank
  double allreduces = 0;           // of one double each
  CommVolume& operator+=(const CommVolume& o) {
    messages += o.messages;
    bytes += o.bytes;
    allreduces += o.allreduces;
    return *this;
  }
  CommVolume operator*(double k) const { return {messages * k, bytes * k, allreduces * k}; }
  CommVolume operator+(const CommVolume& o) const { return {messages + o.messages, bytes + o.bytes, allreduces + o.allreduces}; }
};

struct NetworkModel {
  double latency = 2e-6;    // alpha [s] per message (and per allreduce stage)
  double bandwidth = 10e9;  // beta [B/s] per rank
  // the time of v on P ranks: alpha (messages + allreduces log2 P) + bytes / beta
  double seconds(const CommVolume& v, int ranks) const;
};

// one apply of K on an interior rank of px x py boxes of grid g
CommVolume apply_halo(const GridDims& g, int px, int py);
// the same for a slab rank (px = 1, py = ranks) that has `neighbours` (0..2)
CommVolume slab_apply_halo(const GridDims& g, int neighbours);
// one V-cycle over the hierarchy `grids` (finest first) with Chebyshev degree
CommVolume vcycle_halo(const std::vector<GridDims>& grids, int px, int py, int degree, double agglomerate_nodes = 4096);
// one MG-CG iteration: an apply, a V-cycle, two allreduces
CommVolume mgcg_iteration(const std::vector<GridDims>& grids, int px, int py, int degree);

// an allreduce of n doubles over P ranks (reduce-scatter + allgather:
// 2 (P - 1) / P n doubles sent per rank), counted as one allreduce
CommVolume allreduce_volume(double n, int ranks);
// one Newton step of the contact solver (steklov.hpp, semismooth.hpp) with
// the contact vectors distributed like the grid: `outer` boundary Krylov
// iterations, each an S apply (an inner MG-CG solve of `inner`
// iterations and two plane applies), a K + B V-cycle and 2 allreduces;
// plus two more S applies (the known increments and the update's S du),
// 10 scalar allreduces (norms, counts, the known-increment flag) and the
// allreduce of the K + B block over the bottom plane (4 nx ny doubles)
CommVolume newton_step_comm(const std::vector<GridDims>& grids, int px, int py, int degree, double outer, double inner);

// the most nearly square px x py = ranks with px / py close to nx / ny
void rank_grid(const GridDims& g, int ranks, int& px, int& py);

}  // namespace tresca
