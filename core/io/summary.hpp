// The run-summary schema: one JSON object per solve, written by `tresca`
// (--json; one per row with --table) and by `perf/scaling` (one per level and
// thread count). Keys: level (null for --dims), dims, nodes, contact_nodes,
// dofs, phi, eps, threads, build (ISA line), device (where the kernels ran), mg_precision, newton_iterations,
// converged, reason, residual_history, final_residual, true_residual,
// true_residual_relative, times {setup, condense, solve, recover, total},
// counts {inner_iterations, outer_iterations, operator_applications,
// newton_inner_iterations, outer_limit_hits, watchdog_steps, envelope_steps, last_state_changes,
// inner_tightening,
// fine_matvecs_per_newton_step},
// contact {active, separated, sticking, sliding, ux_min, uz_max, lambda_sum},
// kkt {equilibrium, uz_violation, lambda_violation, complementarity,
// friction_bound, friction_direction, stick_slip}, peak_memory_bytes.
#pragma once
#include <string>

#include "core/contact/run.hpp"
#include "core/io/output.hpp"

namespace tresca {

// The summary as a JSON object builder (callers may append keys, e.g. scaling's speedup).
Json run_summary(const ProblemSpec& spec, const RunResult& R, int threads, const RunOptions& opt);

}  // namespace tresca
