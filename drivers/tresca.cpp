// tresca: 3D linear-elastic contact with Tresca friction by the semismooth*
// Newton method, matrix-free on the contact boundary. See --help.
// Exit status: 0 converged, 1 not converged, 2 bad input, 3 output failure,
// 4 out of memory.
#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <exception>
#include <new>
#include <stdexcept>
#include <string>

#include "core/io/cli.hpp"
#include "core/io/output.hpp"
#include "core/io/problem_file.hpp"
#include "core/io/summary.hpp"
#include "core/io/vtu.hpp"
#include "core/util/profile.hpp"
#include "core/contact/run.hpp"
#include "core/parallel/comm.hpp"
#include "kernels/isa.hpp"

using namespace tresca;

namespace {

const std::string kHelp =
    "usage: tresca [options]\n"
    "  --problem FILE     the case from a JSON problem file (drivers/cases/README.md); the\n"
    "                     options below override it\n"
    "  --level L          mesh level (default 6): ex = ceil(4*2^(L/2)), ey = ez = ceil(2*2^(L/2))\n"
    "  --dims EXxEYxEZ    explicit element counts instead of a level\n"
    "  --phi F            Tresca friction bound per contact node [N] (default 1)\n"
    "  --obstacle KIND:P  a shaped rigid obstacle instead of the plane (lengths in m; x, y in the\n"
    "                     box's frame): plane:GAP,SLOPE_X,SLOPE_Y (gap = GAP + SLOPE_X x + SLOPE_Y y),\n"
    "                     sphere:R,CX,CY,GAP (top GAP below the face at (CX,CY)),\n"
    "                     cylinder:R,CY,GAP (axis along x at y = CY); excludes --gap\n"
    "  --gap-file F.csv   the gap per contact node from a CSV file ix,iy,gap (every contact\n"
    "                     node 1 <= ix <= ex, 0 <= iy <= ey once); excludes --gap, --obstacle\n"
    "  --load-scale S     multiplies all loads (default 1)\n"
    "  --initial F.csv    start Newton from the contact displacement and pressure of a\n"
    "                     --contact-csv file of the same mesh (columns ix,iy,ux,uy,uz,lambda;\n"
    "                     continuation in phi or load, or a restart); the coarser meshes are\n"
    "                     solved too and Newton starts from whichever has the smaller |w|\n"
    "  --coulomb F        Coulomb friction, bound phi_i = F lambda_i per contact node (F >= 0),\n"
    "                     excludes --phi\n"
    "  --coulomb-method newton|lagged|fixed-point  one Newton solve whose step differentiates\n"
    "                     phi = F lambda (default; boundary GMRES), one whose bound follows lambda\n"
    "                     a step late (symmetric, CG), or a fixed point of whole Tresca solves\n"
    "  --gap G            the rigid plane lies G >= 0 metres below the contact face (default 0)\n"
    "  --eps E            stopping tolerance on |w| [N], the residual in consistent units\n"
    "                     (default 1e-6, absolute; --table: on the paper's |v|, its rule (11))\n"
    "  --E E, --nu NU     material (default 2.1e9, 0.277)\n"
    "  --max-newton N     Newton iteration limit (default 50; the coarser meshes of nested\n"
    "                     iteration: " + std::to_string(RunOptions{}.nested_iteration_factor) +
    " N, as their steps cost an eighth)\n"
    "  --merit envelope|residual  the line search's merit far from the solution: the forward-\n"
    "                     backward envelope of the Tresca energy (default) or |w| alone; |w|\n"
    "                     decides near the solution either way\n"
    "  --scaling paper|diagonal  metric of the approximation step: the paper's (forces and\n"
    "                     displacements added as numbers; needs near-exact steps) or the\n"
    "                     diagonal of K_cc per node (default; with --table: paper)\n"
    "  --no-nested        start Newton from x0 = 0 on this mesh (default: nested iteration,\n"
    "                     coarser meshes ceil(e/2) solved first, down to " +
    std::to_string(RunOptions{}.nested_min_contact_nodes) + " contact nodes; a\n"
    "                     Tresca run whose Newton stalls from their solution is solved again\n"
    "                     from x0 = 0; --table never nests)\n"
    "  --outer-pc mg|none preconditioner of the boundary Newton system (default mg)\n"
    "  --mg-degree D                 Chebyshev smoothing steps before and after each coarse\n"
    "                                correction of the V-cycles (default 3, 1..8)\n"
    "  --mg-precision single|double  arithmetic of the multigrid V-cycles (default single;\n"
    "                     the Krylov solvers and all results are double either way)\n"
    "  --threads N        OpenMP threads (default: OMP_NUM_THREADS or all cores)\n"
    "  --device cpu|gpu   where the kernels run (default cpu); gpu (a build with TRESCA_OFFLOAD,\n"
    "                     one rank): every operator, multigrid level, Krylov and contact vector\n"
    "                     in the GPU's memory for the whole solve; only scalars, the coarse\n"
    "                     grid's solve, each Newton step's preconditioner set-up and the\n"
    "                     outputs cross\n"
    "  --json FILE        write the run summary as one JSON object (rows with --table)\n"
    "  --contact-csv FILE one row per contact node\n"
    "  --vtk FILE.vtu     the body for ParaView: the undeformed mesh with the displacement u\n"
    "                     (Warp By Vector shows it deformed), stress and von Mises per cell, and\n"
    "                     FILE_contact.vtu, the contact face (docs/outputs.md); with --table one pair\n"
    "                     FILE_levelL.vtu, FILE_levelL_contact.vtu per level and FILE.pvd to play them\n"
    "  --vtk-every-iteration  with --vtk: also FILE_itK.vtu (+ _contact) at every Newton iterate K\n"
    "                     of the fine mesh and FILE.pvd to play them in ParaView (one extra S apply each)\n"
    "  --vtk-format binary|ascii  VTU encoding: LZMA-compressed appended binary (default) or text\n"
    "  --table A-B        solve levels A..B and print the paper's Table 1 columns\n"
    "  --profile          after the run, time, GB/s and GFLOP/s by solver phase and by kernel launched\n"
    "  --quiet            no progress lines\n"
    "  -h, --help         this text;  --version  the version and the build (ISA, compiler)\n"
    "A run is converged only if its final KKT check agrees (else reason kkt_check_failed).\n"
    "Contact states, separation first: separated, stick (in contact), slip (in contact).\n"
    "Exit status: 0 converged, 1 not converged, 2 bad input, 3 output failure, 4 out of memory.\n";

// The paper's Table 1 (MATLAB): level, n, assembly [s], Cholesky & Schur [s], p, solver [s], iterations
struct PaperRow {
  int level;
  long long n;
  double assembly, schur;
  long long p;
  double solver;
  int iters;
};
const PaperRow kPaper[] = {{1, 225, 0.078, 0.003, 40, 0.017, 5},        {2, 225, 0.031, 0.003, 40, 0.017, 6},
                           {3, 637, 0.094, 0.021, 84, 0.047, 6},        {4, 1377, 0.141, 0.092, 144, 0.101, 6},
                           {5, 4056, 0.516, 0.701, 299, 0.507, 7},      {6, 9537, 1.297, 3.968, 544, 1.928, 7},
                           {7, 27072, 3.156, 32.110, 1104, 9.734, 7},   {8, 70785, 18.672, 1242.211, 2112, 48.275, 8}};
const PaperRow* paper_row(int level) {
  for (const auto& r : kPaper)
    if (r.level == level) return &r;
  return nullptr;
}

}  // namespace

namespace {
// The body and its contact face as one step of a .pvd collection: a .vtu,
// or on a mesh split over the ranks a .pvtu with one piece per rank (a mesh
// too small to split is whole on every rank: rank 0 writes it).
PvdStep write_step(OutputSet& out, double time, const std::string& vtu, const Problem& P, const Slab& rows,
                   const Field<real>& u_full, const ContactFields& cf, VtkFormat format) {
  if (rows.ranks > 1) return {time, {path_stem(vtu) + ".pvtu", write_pvtu(out, vtu, P, rows, u_full, cf, format)}};
  if (Comm::world().rank() != 0) return {time, {vtu, vtu_companion(vtu)}};
  return {time, {vtu, write_vtu(out, vtu, P, u_full, cf, format)}};
}
}  // namespace

namespace {

// What the command line asks for, checked before any work.
struct Command {
  ProblemSpec spec;
  RunOptions opt;
  int threads = 1;
  std::string device = "cpu";  // where the kernels run (apply_device)
  std::string json_path, csv_path, vtk_path, table;
  std::vector<int> table_levels;
  VtkFormat vtk_format = VtkFormat::binary;
  bool every_iteration = false, quiet = false, profile = false;
  std::vector<real> initial_u, initial_lambda;  // --initial: u0 (3p SoA), lambda0 (p)
  std::vector<std::string> no_effect;  // options given that change nothing here (warned about)
  std::string why_double;              // single-precision V-cycles asked, double chosen: why (warned about)
};

// a failed write of an output: exit status 3
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

void reject_with_table(const Args& a, const char* option, const char* why) {
  if (a.has(option)) throw std::invalid_argument(std::string("--table ") + why + "; it takes no " + option);
}

// --initial F.csv: Newton's initial iterate from a --contact-csv file
void read_initial_iterate(const Args& a, Command& c) {
  const std::vector<std::vector<real>> f =
      read_contact_csv(a.str("--initial"), grid_of(c.spec), {"ux", "uy", "uz", "lambda"}, "initial iterate");
  c.initial_u = f[0];
  c.initial_u.insert(c.initial_u.end(), f[1].begin(), f[1].end());
  c.initial_u.insert(c.initial_u.end(), f[2].begin(), f[2].end());
  c.initial_lambda = f[3];
  c.opt.newton.u0 = &c.initial_u;
  c.opt.newton.lambda0 = &c.initial_lambda;
}

// --eps, --max-newton, --outer-pc, --merit, --scaling (with --table: the paper's literal method)
void newton_options_from(const Args& a, bool table, NewtonOptions& n) {
  n.eps = a.real_value("--eps", 1e-6);
  if (!(n.eps > 0)) throw std::invalid_argument("--eps " + a.str("--eps") + " must be > 0");
  const long long mn = a.int_value("--max-newton", 50);
  if (mn < 1 || mn > 100000) throw std::invalid_argument("--max-newton " + a.str("--max-newton") + " must be in 1..100000");
  n.max_iterations = int(mn);
  const std::string pc = a.str("--outer-pc", "mg");
  if (pc != "mg" && pc != "none") throw std::invalid_argument("--outer-pc '" + pc + "' must be mg or none");
  n.outer_pc = pc == "mg" ? OuterPreconditioner::multigrid : OuterPreconditioner::none;
  const std::string merit = a.str("--merit", "envelope");
  if (merit != "envelope" && merit != "residual")
    throw std::invalid_argument("--merit '" + merit + "' must be envelope or residual");
  n.envelope_merit = merit == "envelope";
  const std::string sc = a.str("--scaling", table ? "paper" : "diagonal");
  if (sc != "paper" && sc != "diagonal") throw std::invalid_argument("--scaling '" + sc + "' must be paper or diagonal");
  if (sc != "paper") return;
  const NewtonOptions paper = NewtonOptions::paper_method();
  n.scaling = paper.scaling;
  n.forcing_max = paper.forcing_max;
  if (table) {  // the paper's literal method: its stopping rule, full steps, its kink rule
    n.stop = paper.stop;
    n.line_search = paper.line_search;
    n.kink_contact = paper.kink_contact;
  }
}

// --mg-precision, --mg-degree
void multigrid_options_from(const Args& a, MGOptions& mg) {
  const std::string prec = a.str("--mg-precision", "single");
  if (prec != "single" && prec != "double")
    throw std::invalid_argument("--mg-precision '" + prec + "' must be single or double");
  mg.precision = prec == "single" ? Precision::single_precision : Precision::double_precision;
  const long long degree = a.int_value("--mg-degree", mg.degree);
  if (degree < 1 || degree > 8) throw std::invalid_argument("--mg-degree " + a.str("--mg-degree") + " must be in 1..8");
  mg.degree = int(degree);
}

// --phi (Tresca, over a problem file's Coulomb), --coulomb F, --coulomb-method
void friction_from(const Args& a, bool table, FrictionLaw& law) {
  if (a.has("--phi")) law = tresca_friction();
  law.method = coulomb_method_from(a.str("--coulomb-method", to_string(FrictionLaw{}.method)), "--coulomb-method");
  if (!a.has("--coulomb")) return;
  const real F = a.real_value("--coulomb", 0);
  if (!(F >= 0) || !std::isfinite(F))
    throw std::invalid_argument("--coulomb " + a.str("--coulomb") + " must be a friction coefficient >= 0");
  law = coulomb_friction(F, law.method);
  if (a.has("--phi")) throw std::invalid_argument("--coulomb and --phi exclude each other (Coulomb: phi_i = F lambda_i)");
  if (table) throw std::invalid_argument("--table reproduces the paper's Tresca case; it takes no --coulomb");
}

// every output, the derived files included, writable and distinct before the solve
void check_outputs(const Command& c, const Comm& comm) {
  std::vector<std::pair<std::string, std::string>> outputs;  // (path, what)
  if (!c.json_path.empty()) outputs.push_back({c.json_path, "--json"});
  if (!c.csv_path.empty()) outputs.push_back({c.csv_path, "--contact-csv"});
  const std::string& vtk = c.vtk_path;
  if (!vtk.empty() && c.table.empty()) {
    if (comm.distributed()) {  // ParaView's parallel format
      outputs.push_back({path_stem(vtk) + ".pvtu", "--vtk's index"});
      outputs.push_back({pvtu_piece_name(vtk, comm.rank()), "--vtk's piece"});
    } else {
      outputs.push_back({vtk, "--vtk"});
    }
    outputs.push_back({vtu_companion(vtk), "--vtk's contact file"});
  }
  if (c.every_iteration) {
    outputs.push_back({pvd_name(vtk), "--vtk's collection"});
    outputs.push_back({vtu_step_name(vtk, "_it0"), "--vtk's iterates"});
  }
  if (!vtk.empty() && !c.table.empty()) {
    outputs.push_back({pvd_name(vtk), "--vtk's collection"});
    for (int L : c.table_levels) {
      const std::string v = vtu_step_name(vtk, "_level" + std::to_string(L));
      outputs.push_back({v, "--vtk's level " + std::to_string(L)});
      outputs.push_back({vtu_companion(v), "--vtk's level " + std::to_string(L) + " contact file"});
    }
  }
  for (size_t i = 0; i < outputs.size(); ++i) {
    check_writable(outputs[i].first);
    for (size_t j = 0; j < i; ++j)
      if (same_file(outputs[i].first, outputs[j].first))
        throw std::invalid_argument(outputs[i].second + " and " + outputs[j].second + " name the same file '" +
                                    outputs[i].first + "'");
  }
}

// The command line (and a problem file) into c (in place: its options point
// at its own initial iterate); std::invalid_argument names what is wrong
void parse_command(const Args& a, const Comm& comm, Command& c) {
  c.threads = apply_threads(a);
  c.device = apply_device(a, comm);
  c.table = a.str("--table");
  const bool table = !c.table.empty();
  if (table) {
    for (const char* o : {"--level", "--dims", "--contact-csv"}) reject_with_table(a, o, "runs its own levels");
    reject_with_table(a, "--problem", "reproduces the paper's problem");
    reject_with_table(a, "--gap-file", "reproduces the paper's problem");
    reject_with_table(a, "--initial", "starts every level from x0 = 0");
  }
  ProblemFile file;
  if (a.has("--problem")) {
    file = read_problem_file(a.str("--problem"));
    c.opt.friction = file.friction;
  }
  c.spec = spec_from_args(a, 6, a.has("--problem") ? &file.spec : nullptr);
  if (a.has("--gap-file")) {
    if (a.has("--gap") || a.has("--obstacle")) throw std::invalid_argument("--gap-file excludes --gap and --obstacle");
    c.opt.contact = contact_conditions(c.spec);
    c.opt.contact.gap = read_gap_csv(a.str("--gap-file"), grid_of(c.spec));
  }
  if (a.has("--initial")) read_initial_iterate(a, c);
  newton_options_from(a, table, c.opt.newton);
  multigrid_options_from(a, c.opt.mg);
  c.why_double = keep_vcycles_in_range(c.spec, c.opt.mg);
  friction_from(a, table, c.opt.friction);
  c.opt.nested = !a.has("--no-nested") && !table;  // --table: the paper's cold start
  if (a.has("--coulomb-method") && !c.opt.friction.is_coulomb())
    c.no_effect.push_back("--coulomb-method chooses how Coulomb friction is solved; this run is Tresca (--coulomb F)");
  if (a.has("--no-nested") && table) c.no_effect.push_back("--no-nested: --table never nests (the paper's cold start)");
  if (a.has("--merit") && !envelope_applies(c.opt.newton.scaling, c.opt.friction))
    c.no_effect.push_back("--merit: the envelope is the merit of the scaled step (--scaling diagonal) with a bound that "
                          "does not follow lambda (Tresca, --coulomb-method fixed-point); this run uses |w| alone");
  c.quiet = a.has("--quiet");
  c.profile = a.has("--profile");
  c.json_path = a.str("--json");
  c.csv_path = a.str("--contact-csv");
  c.vtk_path = a.str("--vtk");
  if (a.has("--vtk-format") && c.vtk_path.empty())
    throw std::invalid_argument("--vtk-format sets the encoding of --vtk's files; it needs --vtk FILE.vtu");
  c.vtk_format = parse_vtk_format(a.str("--vtk-format", "binary"), "--vtk-format");
  if (table) c.table_levels = parse_level_range(c.table);
  c.every_iteration = a.has("--vtk-every-iteration");
  if (c.every_iteration && (c.vtk_path.empty() || table))
    throw std::invalid_argument("--vtk-every-iteration needs --vtk FILE.vtu (and no --table)");
  check_outputs(c, comm);
}

// inputs that run but may not give what the user expects
void warn_about(const Command& c) {
  for (const std::string& w : c.no_effect) std::fprintf(stderr, "tresca: warning: no effect: %s\n", w.c_str());
  if (c.opt.newton.scaling == StepScaling::paper && (c.spec.E < 1e6 || c.spec.E > 1e12))
    std::fprintf(stderr,
                 "tresca: warning: --scaling paper adds forces [N] and displacements [m] as numbers, which suits the\n"
                 "  paper's E = 2.1e9 Pa; at E = %g Pa they differ by many orders and Newton may stagnate\n"
                 "  (--scaling diagonal, the default outside --table, does not depend on the units)\n",
                 c.spec.E);
  if (c.spec.nu > 0.49)
    std::fprintf(stderr,
                 "tresca: warning: nu = %.9g is nearly incompressible: Q1 elements lock and the multigrid inner solver "
                 "degrades (it may fail to converge)\n",
                 c.spec.nu);
  if (!c.why_double.empty()) std::fprintf(stderr, "tresca: note: %s\n", c.why_double.c_str());
  const real flat = unresolved_anisotropy(grid_of(c.spec), c.opt.mg.coarse_nodes);
  if (flat > 4)
    std::fprintf(stderr,
                 "tresca: warning: the elements are up to %.3g times wider than the body is thick (a thin plate of "
                 "wide elements): multigrid cannot coarsen that away and the Newton steps' solver may stall or fail; "
                 "elements at most 4 times wider than the thickness avoid it\n",
                 flat);
  // a sphere or cylinder placed off the face (a unit slip, a sign): the body
  // then moves freely, a valid run that is rarely what was meant
  const ProblemSpec& s = c.spec;
  if (s.obstacle.kind != Obstacle::Kind::plane && c.opt.contact.gap.empty()) {
    const std::vector<real> gap = contact_conditions(s).gap;
    if (std::none_of(gap.begin(), gap.end(), [](real g) { return g < Obstacle::kNoObstacle; }))
      std::fprintf(stderr,
                   "tresca: warning: the %s lies under none of the %zu contact nodes (the contact face spans x in "
                   "(%g, %g], y in [%g, %g] m): nothing can touch it\n",
                   to_string(s.obstacle.kind), gap.size(), s.x0, s.x0 + s.lx, s.y0, s.y0 + s.ly);
  }
}

// the progress lines of a run that is not --quiet
void show_progress(RunOptions& opt) {
  opt.phase_done = [](const char* phase, double sec) {
    std::printf("  %s: %.2f s\n", phase, sec);
    std::fflush(stdout);
  };
  opt.nested_done = [device_run = launch_on_device()](const NestedLevel& l) {
    // (a device run solves its small coarser meshes on the host: say where)
    std::printf("  nested: mesh %s solved in %d Newton steps%s%s: %.2f s\n", dims_string(l.spec).c_str(),
                l.newton_iterations, !device_run ? "" : l.on_device ? " on the gpu" : " on the cpu",
                l.converged ? "" : " (not converged: not used)", l.seconds);
    std::fflush(stdout);
  };
  opt.newton.progress = [](const NewtonProgress& p) {
    std::printf("  it %2d  |v| %10.3e  step %5.3f  contact %7lld  separated %7lld  stick %7lld  slip %7lld  inner %7lld  outer %5lld  %8.2f s\n",
                p.iteration, p.residual, p.step_length, (long long)p.active, (long long)p.separated,
                (long long)p.sticking, (long long)p.sliding, p.inner_iterations, p.outer_iterations, p.elapsed);
    std::fflush(stdout);
  };
}

// --table: the paper's levels one after another from x0 = 0 (its literal
// method, set up by parse_command), one row each beside the paper's
// figures; exit status 0 if every level converged, 1 if not
int run_table(const Command& c, const Comm& comm) {
  for (int L : c.table_levels) check_memory(spec_for_level(L));
  OutputSet out;  // the levels' VTU files and the collection, published with the JSON
  std::vector<PvdStep> steps;
  std::printf("%5s %9s %9s %9s %7s %9s %5s %5s | paper: %9s %9s %9s %5s | %s\n", "level", "n", "setup", "condense",
              "p", "solve", "iters", "conv", "assembly", "schur", "solver", "iters", "true residual (rel)");
  Json rows = Json::array();
  bool all = true;
  for (int L : c.table_levels) {
    ProblemSpec s = spec_for_level(L);
    s.phi = c.spec.phi;
    s.E = c.spec.E;
    s.nu = c.spec.nu;
    RunOptions o = c.opt;
    o.newton.progress = nullptr;
    o.phase_done = nullptr;
    o.recover_interior = !c.vtk_path.empty();
    profile_reset();  // each row's profile its own
    const RunResult R = run_tresca(s, o);
    if (!c.vtk_path.empty()) {
      const std::string v = vtu_step_name(c.vtk_path, "_level" + std::to_string(L));
      const ContactFields cf{&R.newton.u, &R.newton.lambda, &R.report.r, &R.report.status, &R.contact.phi,
                             &R.contact.gap};
      steps.push_back(write_step(out, double(L), v, *R.problem, R.slab, R.u_full, cf, c.vtk_format));
    }
    const PaperRow* pr = paper_row(L);
    char pbuf[128] = "        -         -         -     -";
    if (pr) std::snprintf(pbuf, sizeof pbuf, "%9.3f %9.3f %9.3f %5d", pr->assembly, pr->schur, pr->solver, pr->iters);
    std::printf("%5d %9lld %9.3f %9.3f %7lld %9.3f %5d %5s | paper: %s | %.2e (%.1e)\n", L,
                (long long)R.problem->nodes(), R.times.setup, R.times.condense, (long long)R.problem->contact_nodes(),
                R.times.solve, R.newton.iterations, R.converged() ? "yes" : "NO", pbuf, R.report.true_residual,
                R.report.true_residual_relative);
    std::fflush(stdout);
    all = all && R.converged();
    rows.push_back(run_summary(s, R, c.threads, c.opt));
  }
  try {
    if (!c.json_path.empty()) write_text(out, c.json_path, json_text(rows));
    if (!c.vtk_path.empty() && comm.rank() == 0) write_pvd(out, pvd_name(c.vtk_path), steps);
    out.finish();
    comm.barrier();  // every rank's pieces complete on disk before any is published
    out.publish();
  } catch (const std::exception& e) {
    throw OutputError(e.what());
  }
  if (!c.vtk_path.empty() && !c.quiet)
    std::printf("wrote %s (levels %d-%d)\n", pvd_name(c.vtk_path).c_str(), c.table_levels.front(),
                c.table_levels.back());
  return all ? 0 : 1;
}

// the run's first lines: the problem, the memory estimate, the build and where the threads run
void print_header(const Command& c, const ThreadPlacement& placement, const Comm& comm) {
  const ProblemSpec& spec = c.spec;
  char friction[64];
  if (c.opt.friction.is_coulomb())
    std::snprintf(friction, sizeof friction, "Coulomb F %g", c.opt.friction.F);
  else
    std::snprintf(friction, sizeof friction, "phi %g", spec.phi);
  std::printf("tresca: mesh %s (level %s), %lld nodes, %lld contact nodes, %lld dofs, %s, obstacle %s, eps %g, %d threads%s\n",
              dims_string(spec).c_str(), spec.level >= 0 ? std::to_string(spec.level).c_str() : "-",
              (long long)spec.nodes(), (long long)spec.contact_nodes(), (long long)spec.free_dofs(), friction,
              to_string(spec.obstacle.kind), c.opt.newton.eps, c.threads,
              comm.distributed() ? (" per rank x " + std::to_string(comm.size()) + " MPI ranks (" + run_rank_layout(spec) + ")")
                                     .c_str() : "");
  std::printf("        estimated peak memory %.2f GB%s; kernels: %s; %s\n",
              run_memory_per_rank(spec) / 1e9,
              comm.distributed() ? " per rank" : launch_on_device() ? " (a device run: nearly all in the device's)" : "",
              build_info().c_str(), omp_wait_setting().c_str());
  std::printf("        %s; %s; kernels on %s\n", placement.describe().c_str(), huge_page_setting().c_str(),
              c.device.c_str());
}

// how the friction law's iteration ended (Coulomb)
void print_coulomb(const Command& c, const RunResult& R) {
  const CoulombResult& C = R.coulomb_loop;
  if (R.coulomb_fallback)
    std::printf("Coulomb F = %g: the Newton solve did not converge; the fixed point of Tresca solves took over\n",
                R.friction.F);
  if (c.opt.friction.bound_follows_lambda() && !R.coulomb_fallback) {
    std::printf("Coulomb F = %g, the bound phi_i = F lambda_i %s at every Newton step; max |phi_i - F lambda_i| = %.2e N\n",
                R.friction.F, c.opt.friction.differentiates_bound() ? "differentiated" : "updated",
                R.coulomb_consistency);
    return;
  }
  std::printf("Coulomb F = %g: %s after %d Tresca solves, %lld Newton steps in all (reason: %s); changes of phi:",
              R.friction.F, C.converged() ? "converged" : "NOT CONVERGED", C.iterations, C.newton_steps,
              to_string(C.reason));
  for (real ch : C.changes) std::printf(" %.1e", ch);
  std::printf("\nthe last Tresca solve (phi_i = F lambda_i of the one before, max |phi_i - F lambda_i| = %.2e N):\n",
              R.coulomb_consistency);
}

// the run's report: convergence, the true residual, the KKT check, the contact sets, work and times
void print_report(const Command& c, const RunResult& R, const Comm& comm) {
  const NewtonResult& N = R.newton;
  const FinalReport& F = R.report;
  const real eps = c.opt.newton.eps;
  char last[64] = "n/a (no approximation step)", tolerance[32] = "n/a";
  if (!N.history.empty()) {
    std::snprintf(last, sizeof last, "%.3e %s", N.history.back(), N.stop == StopRule::consistent ? "N" : "(the paper's rule)");
    std::snprintf(tolerance, sizeof tolerance, "%.1e", N.tolerance);
  }
  if (R.coulomb()) print_coulomb(c, R);
  std::printf("%s after %d Newton iterations (reason: %s), final |v| %s (tolerance %s)\n",
              R.converged() ? "converged" : "NOT CONVERGED", N.iterations, R.reason().c_str(), last, tolerance);
  if (N.history.empty() && N.reason == NewtonReason::inner_failure)
    std::printf("note: the inner solver (multigrid CG on the body's interior) did not converge for the condensed\n"
                "      load b~, so Newton did not start: the lines below are of u = 0, with |b~| unknown\n");
  std::printf("true residual (fresh S u - b~): %.3e absolute, %.3e relative to |b~| %s %.3e%s\n", F.true_residual,
              F.true_residual_relative, R.btilde_estimated ? "~" : "=", F.btilde_norm,
              R.btilde_estimated ? " (from the coarser mesh)" : "");
  if ((N.reason == NewtonReason::stagnation || N.reason == NewtonReason::iteration_limit) && !N.history.empty() &&
      N.history.back() <= 1e-9 * N.history.front())
    std::printf("note: |v| stagnated at %.1e of its initial value, the accuracy the inner solves attain: eps = %.1e\n"
                "      is out of reach for this problem's magnitudes (--eps %.0e would be met)\n",
                N.history.back() / N.history.front(), eps, std::pow(10.0, std::ceil(std::log10(2 * N.history.back()))));
  if (N.residual_floor > 0) {
    std::printf("note: eps = %.1e N is finer than r = S u - b~ resolves for this problem: |v| settled at or below\n"
                "      %.1e N (%.1e |b~|), no contact state changed for %d Newton steps; converged to that\n"
                "      level, confirmed with a fresh r (--eps %.0e asks for no more)\n",
                eps, N.residual_floor, N.residual_floor / F.btilde_norm, c.opt.newton.stagnation_window,
                std::pow(10.0, std::ceil(std::log10(N.residual_floor))));
    if (N.floor_measured > 0)
      std::printf("note: that level is above 1e-10 |b~|: two fresh r at x, one warm and one from a cold start, differed\n"
                  "      by %.1e N (%.1e |b~|), what r resolves here (a small difference of large terms); the level\n"
                  "      is within 4 times that, the spread of a fresh r's error\n",
                  N.floor_measured, N.floor_measured / F.btilde_norm);
  } else if (N.converged() && !(F.true_residual <= eps))
    std::printf("note: the true residual is above eps = %.1e = %.1e |b|, finer than the inner solves resolve (~1e-12 |b|)\n",
                eps, eps / F.btilde_norm);
  else if (N.converged() && F.resolution > eps)
    std::printf("note: eps = %.1e is finer than the check resolves (the body's equilibrium to %.0e: r to ~%.1e N);\n"
                "      the true residual is consistent with eps, not a proof of it\n",
                eps, F.resolution / F.btilde_norm, F.resolution);
  std::printf("KKT: equilibrium %.2e N, uz<0 %.2e m, lambda<0 %.2e N, lambda*uz %.2e Nm, |r_t|-phi %.2e N, direction %.2e N, stick slip %.2e m\n",
              F.equilibrium, F.uz_violation, F.lambda_violation, F.complementarity, F.friction_bound,
              F.friction_direction, F.stick_slip);
  std::printf("KKT in consistent units: largest %.2e N, |w| %.2e N, tolerance %.2e N: %s", F.kkt_force,
              F.true_residual_consistent, F.tolerance, F.kkt_ok ? "ok" : "FAILED");
  if (F.slip_unresolved > 0)
    std::printf(" (%lld sliding nodes slip less than the tolerance: direction not checked)", (long long)F.slip_unresolved);
  std::printf("\n");
  std::printf("contact: %lld active, %lld separated, %lld sticking, %lld sliding; min ux %.6e, max uz %.6e, sum lambda %.6e\n",
              (long long)F.active, (long long)F.separated, (long long)F.sticking, (long long)F.sliding, F.ux_min,
              F.uz_max, F.lambda_sum);
  std::printf("work: %lld inner CG iterations, %lld outer CG iterations, %lld S applications\n", R.inner_iterations,
              N.outer_iterations, N.operator_applications);
  if (N.outer_limit_hits > 0)
    std::printf("note: %d Newton steps were taken with an outer CG stopped at its iteration limit\n", N.outer_limit_hits);
  if (N.reason == NewtonReason::iteration_limit && N.last_state_changes > 0)
    std::printf("note: the last step still changed the state of %lld contact nodes (the active set was still moving); "
                "--max-newton N allows more steps\n",
                (long long)N.last_state_changes);
  if (N.watchdog_steps > 0)
    std::printf("note: %d Newton steps were taken whole where no step length decreased |w| (the line search's watchdog)\n",
                N.watchdog_steps);
  if (!R.cold_restart_after.empty())
    std::printf("note: Newton from the coarser mesh's solution ended %s after %d steps; the run was solved again\n"
                "      from x0 = 0 (the lines above: both solves; the work and the total time: both)\n",
                R.cold_restart_after.c_str(), R.cold_restart_steps);
  if (R.resumed_from >= 0)
    std::printf("note: the final check did not confirm the stop after step %d (|w| <= eps, a KKT field above it):\n"
                "      Newton went on to eps %.1e, %d more steps\n",
                R.resumed_from, R.resumed_eps, N.iterations - R.resumed_from);
  if (N.redone_steps > 0)
    std::printf("note: %d Newton steps were solved again with tighter inner solves (a solve stopped at the outer "
                "CG's limit short of its target, or its check found it worse than no step)\n",
                N.redone_steps);
  if (N.monotone_from >= 0)
    std::printf("note: from Newton step %d on each step had to lower its merit (a monotone line search): the "
                "non-monotone search had made no progress\n",
                N.monotone_from);
  if (N.inner_tightening > 1)
    std::printf(
        "note: the Newton steps' inner solves were tightened %.3gx: steps solved with the default inner "
        "tolerance missed their accuracy when checked with a fresh S du (S is much smaller than its terms, "
        "e.g. nu near -1 or a thin plate)\n",
        N.inner_tightening);
  char device_peak[64] = "";
  if (R.peak_device_memory > 0)
    std::snprintf(device_peak, sizeof device_peak, ", device Fields at most %.2f GB", R.peak_device_memory / 1e9);
  std::printf("work: %.1f fine-grid matvec equivalents per Newton step; peak memory %.2f GB%s%s\n",
              R.fine_matvecs_per_newton_step(), R.peak_memory / 1e9, comm.distributed() ? " (largest rank)" : "",
              device_peak);
  std::printf("times [s]: nested %.3f, setup %.3f, condense %.3f, solve %.3f, recover %.3f, total %.3f\n",
              R.times.nested, R.times.setup, R.times.condense, R.times.solve, R.times.recover, R.times.total);
  if (comm.distributed()) {
    const CommCounters& cc = comm_counters();
    std::printf("communication (rank 0, whole run): %lld messages, %.1f MB point-to-point, %lld allreduces, "
                "%lld other collectives\n", cc.messages, cc.bytes / 1e6, cc.allreduces, cc.collectives);
  }
  if (c.profile)
    std::printf("\nkernel profile (%s, %d threads; kernels on %s)\n%s", build_info().c_str(), c.threads,
                c.device.c_str(), profile_table(R.times.total).c_str());
}

// --vtk-every-iteration: each Newton iterate's files, into `out` and `steps`;
// a failed write is kept in `error` (reported after the solve, exit 3)
void write_iterates(const Command& c, RunOptions& opt, OutputSet& out, std::vector<PvdStep>& steps, std::string& error) {
  opt.iterate_done = [&c, &out, &steps, &error](const Iterate& it) {
    if (!error.empty()) return;
    try {
      const NewtonProgress& pr = *it.progress;
      const ContactFields cf{pr.u, pr.lambda, pr.r, pr.status, pr.phi, it.gap};
      const std::string v = vtu_step_name(c.vtk_path, "_it" + std::to_string(it.step));
      steps.push_back(write_step(out, double(it.step), v, *it.problem, *it.slab, *it.u_full, cf, c.vtk_format));
      out.finish();
    } catch (const std::exception& e) {
      error = e.what();
    }
  };
}

// all of the run's outputs, or none of them (output.hpp: OutputSet)
void write_outputs(const Command& c, const RunResult& R, OutputSet& out, const std::vector<PvdStep>& steps,
                   const std::string& iterate_error, const Comm& comm) {
  try {
    const NewtonResult& N = R.newton;
    const ContactFields cf{&N.u, &N.lambda, &R.report.r, &R.report.status, &R.contact.phi, &R.contact.gap};
    if (!iterate_error.empty()) throw std::runtime_error(iterate_error);
    if (c.every_iteration && comm.rank() == 0) write_pvd(out, pvd_name(c.vtk_path), steps);
    if (!c.json_path.empty()) write_text(out, c.json_path, json_text(run_summary(c.spec, R, c.threads, c.opt)));
    if (!c.csv_path.empty()) write_contact_csv(out, c.csv_path, *R.problem, cf);
    std::vector<std::string> wrote;
    if (!c.vtk_path.empty()) wrote = write_step(out, 0, c.vtk_path, *R.problem, R.slab, R.u_full, cf, c.vtk_format).files;
    out.finish();
    comm.barrier();  // every rank's pieces complete on disk before any is published
    out.publish();
    if (!c.vtk_path.empty() && !c.quiet)
      std::printf("wrote %s%s and %s\n", wrote[0].c_str(),
                  R.slab.ranks > 1 ? (" (with " + std::to_string(R.slab.ranks) + " pieces " +
                                      pvtu_piece_name(c.vtk_path, 0) + ", ...)").c_str()
                                   : "",
                  wrote[1].c_str());
  } catch (const std::exception& e) {
    throw OutputError(e.what());
  }
  // a full or closed stdout lost the report: not a success
  if (std::fflush(stdout) != 0 || std::ferror(stdout))
    throw OutputError("writing the report to standard output failed");
}

// one solve: header, progress, report, outputs; the exit status
int run(Command& c, const Comm& comm) {
  if (comm.rank() != 0) c.json_path = c.csv_path = "";  // outputs: rank 0's (and a piece of the VTU each)
  warn_about(c);
  warn_if_cores_busy();
  if (!c.quiet) show_progress(c.opt);
  if (!c.table.empty()) return run_table(c, comm);
  const ThreadPlacement placement = thread_placement();
  if (placement.cpus < int(placement.thread_cpus.size()))
    std::fprintf(stderr, "tresca: warning: %d OpenMP threads may run on only %d CPUs (%s): they will share them\n",
                 int(placement.thread_cpus.size()), placement.cpus, placement.describe().c_str());
  if (!c.quiet) print_header(c, placement, comm);
  OutputSet out;
  std::vector<PvdStep> steps;
  std::string iterate_error;
  if (c.every_iteration) write_iterates(c, c.opt, out, steps, iterate_error);
  const RunResult R = run_tresca(c.spec, c.opt);
  print_report(c, R, comm);
  write_outputs(c, R, out, steps, iterate_error, comm);
  if (!R.converged()) std::fprintf(stderr, "tresca: not converged (%s)\n", R.reason().c_str());
  return R.converged() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  // Under mpirun with several ranks every rank runs this main: the 3D work is
  // split into y-slabs (steklov.hpp), the contact iteration is the same on
  // every rank, and rank 0 alone prints and writes the outputs.
  MpiSession mpi(argc, argv);
  const Comm& comm = Comm::world();
  if (comm.rank() != 0) {
    if (!std::freopen("/dev/null", "w", stdout) || !std::freopen("/dev/null", "w", stderr)) return 3;
  }
  Command c;
  try {
    const Args a(argc, argv,
                 {"--level", "--dims", "--phi", "--gap", "--eps", "--E", "--nu", "--max-newton", "--threads", "--json",
                  "--contact-csv", "--vtk", "--table", "--outer-pc", "--mg-precision", "--mg-degree", "--scaling",
                  "--coulomb", "--coulomb-method", "--obstacle", "--load-scale", "--problem", "--gap-file",
                  "--vtk-format", "--initial", "--device", "--merit"},
                 {"--quiet", "--profile", "--no-nested", "--vtk-every-iteration"});
    if (answered_help_or_version(a, "tresca", kHelp.c_str())) return 0;
    parse_command(a, comm, c);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tresca: error: %s\n", e.what());
    return 2;
  }
  try {
    return run(c, comm);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "tresca: error: %s\n", e.what());
    return 2;
  } catch (const OutputError& e) {
    std::fprintf(stderr, "tresca: error: %s\n", e.what());
    return 3;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "tresca: error: out of memory (the estimate is printed first; try a smaller mesh)\n");
    return 4;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tresca: error: %s\n", e.what());
    return 1;
  }
}
