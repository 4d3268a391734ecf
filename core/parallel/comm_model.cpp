#include "core/parallel/comm_model.hpp"

#include <cmath>

namespace tresca {

double NetworkModel::seconds(const CommVolume& v, int ranks) const {
  const double stages = ranks > 1 ? std::ceil(std::log2(double(ranks))) : 0;
  return latency * (v.messages + v.allreduces * stages) + v.bytes / bandwidth;
}

CommVolume apply_halo(const GridDims& g, int px, int py) {
  const double lx = double(g.nx()) / px, ly = double(g.ny()) / py, nz = double(g.nz());
  const double per_node = 3 * sizeof(double);
  CommVolume v;
  if (px > 1) v.messages += 2, v.bytes += 2 * ly * nz * per_node;
  if (py > 1) v.messages += 2, v.bytes += 2 * lx * nz * per_node;
  if (px > 1 && py > 1) v.messages += 4, v.bytes += 4 * nz * per_node;
  return v;
}

CommVolume slab_apply_halo(const GridDims& g, int neighbours) {
  return {double(neighbours), double(neighbours) * double(g.nx() * g.nz()) * 3 * sizeof(double), 0};
}

CommVolume vcycle_halo(const std::vector<GridDims>& grids, int px, int py, int degree, double agglomerate_nodes) {
  CommVolume v;
  const int P = px * py;
  for (size_t l = 0; l < grids.size(); ++l) {
    const double per_rank = double(grids[l].nodes()) / P;
    if (P > 1 && per_rank < agglomerate_nodes) {
      // gathered onto one rank and solved there: a gather and a scatter of the level's vector
      v.messages += 2;
      v.bytes += 2 * per_rank * 3 * sizeof(double);
      break;
    }
    const CommVolume a = apply_halo(grids[l], px, py);
    const bool coarsest = l + 1 == grids.size();
    v += a * (coarsest ? 0.0 : double(2 * degree + 1 + 2));  // smoother, residual, two transfers
  }
  return v;
}

CommVolume mgcg_iteration(const std::vector<GridDims>& grids, int px, int py, int degree) {
  CommVolume v = apply_halo(grids.front(), px, py);
  v += vcycle_halo(grids, px, py, degree);
  v.allreduces += 2;
  return v;
}

CommVolume allreduce_volume(double n, int ranks) {
  if (ranks <= 1) return {};
  return {0, 2.0 * (ranks - 1) / ranks * n * sizeof(double), 1};
}

CommVolume newton_step_comm(const std::vector<GridDims>& grids, int px, int py, int degree, double outer, double inner) {
  const int P = px * py;
  if (P <= 1) return {};
  const GridDims& g = grids.front();
  CommVolume s_apply = mgcg_iteration(grids, px, py, degree) * inner;
  s_apply += apply_halo(g, px, py) * 2.0;
  CommVolume it = s_apply + vcycle_halo(grids, px, py, degree);
  it.allreduces += 2;
  CommVolume step = it * outer;
  step += s_apply * 2.0;
  step.allreduces += 10;
  step += allreduce_volume(4.0 * double(g.nx() * g.ny()), P);
  return step;
}

void rank_grid(const GridDims& g, int ranks, int& px, int& py) {
  // the factorisation with the least halo bytes per apply
  px = 1;
  py = ranks;
  double best = apply_halo(g, px, py).bytes;
  for (int a = 2; a <= ranks; ++a) {
    if (ranks % a) continue;
    const double b = apply_halo(g, a, ranks / a).bytes;
    if (b < best) best = b, px = a, py = ranks / a;
  }
}

}  // namespace tresca
