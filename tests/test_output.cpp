// What users read, value by value: the contact CSV, both VTU files and the
// JSON run summary against the solver's own arrays, on a small case where
// nodes stick, slide and separate. The files are parsed back independently.
#include <gtest/gtest.h>
#include <filesystem>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/contact/run.hpp"
#include "core/io/output.hpp"
#include "core/io/summary.hpp"
#include "core/io/vtu.hpp"
#include "kernels/contact_maps.hpp"

namespace tresca {

namespace {

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// the numbers of the DataArray named `name` (or the first one after `after`)
std::vector<double> data_array(const std::string& xml, const std::string& name, const std::string& after = "") {
  size_t at = after.empty() ? xml.find("Name=\"" + name + "\"") : xml.find(after);
  EXPECT_NE(at, std::string::npos) << name << after;
  if (at == std::string::npos) return {};
  at = xml.find('>', after.empty() ? at : xml.find("<DataArray", at)) + 1;
  const size_t end = xml.find("</DataArray>", at);
  std::istringstream is(xml.substr(at, end - at));
  std::vector<double> v;
  double x;
  while (is >> x) v.push_back(x);
  return v;
}

// VTK status codes, from the node's status bits (output.hpp)
int status_code(std::uint8_t s) { return !(s & kContact) ? 1 : (s & kStick) ? 2 : 3; }

class OutputFiles : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    spec_ = new ProblemSpec(spec_for_dims(12, 6, 6));
    spec_->phi = 3e6;
    spec_->obstacle.slope_x = 1e-3;  // a gap per node (0 to 2 mm along x), so the CSV's gap column is tested
    RunOptions o;
    R_ = new RunResult(run_tresca(*spec_, o));
  }
  static void TearDownTestSuite() {
    delete R_;
    delete spec_;
  }
  ContactFields fields() const {
    return {&R_->newton.u, &R_->newton.lambda, &R_->report.r, &R_->report.status, &R_->contact.phi, &R_->contact.gap};
  }
  static ProblemSpec* spec_;
  static RunResult* R_;
};
ProblemSpec* OutputFiles::spec_ = nullptr;
RunResult* OutputFiles::R_ = nullptr;

}  // namespace

TEST_F(OutputFiles, TheCaseHasEveryKindOfContactNode) {
  ASSERT_TRUE(R_->newton.converged());
  EXPECT_GT(R_->report.sticking, 0);
  EXPECT_GT(R_->report.sliding, 0);
  EXPECT_GT(R_->report.separated, 0);
}

TEST_F(OutputFiles, ContactCsvRowsAreTheSolversValues) {
  const std::string path = ::testing::TempDir() + "tresca_out.csv";
  {
    OutputSet out;
    write_contact_csv(out, path, *R_->problem, fields());
    out.publish();
  }
  std::istringstream is(slurp(path));
  std::string line;
  std::getline(is, line);
  EXPECT_EQ(line, "ix,iy,x,y,ux,uy,uz,lambda,phi,gap,contact,stick");
  const Problem& P = *R_->problem;
  const index p = P.contact_nodes();
  const auto &u = R_->newton.u, &lam = R_->newton.lambda;
  const auto& st = R_->report.status;
  index rows = 0;
  while (std::getline(is, line)) {
    double v[12];
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", v, v + 1, v + 2, v + 3, v + 4,
                          v + 5, v + 6, v + 7, v + 8, v + 9, v + 10, v + 11),
              12)
        << line;
    const index i = rows++;
    ASSERT_LT(i, p);
    const index ix = 1 + i % P.grid.ex, iy = i / P.grid.ex;
    EXPECT_EQ(v[0], ix);
    EXPECT_EQ(v[1], iy);
    EXPECT_NEAR(v[2], P.grid.x0 + ix * P.grid.hx(), 1e-9);
    EXPECT_NEAR(v[3], P.grid.y0 + iy * P.grid.hy(), 1e-9);
    // %.17g round-trips doubles exactly
    EXPECT_EQ(v[4], u[i]) << "u_x of node " << i;
    EXPECT_EQ(v[5], u[p + i]) << "u_y of node " << i;
    EXPECT_EQ(v[6], u[2 * p + i]) << "u_z of node " << i;
    EXPECT_EQ(v[7], lam[i]);
    EXPECT_EQ(v[8], R_->contact.phi[i]);
    EXPECT_EQ(v[9], R_->contact.gap[i]);
    EXPECT_EQ(v[10], (st[i] & kContact) ? 1 : 0);
    // stick: sticking in contact (separation first, contact_state)
    EXPECT_EQ(v[11], (st[i] & kContact) && (st[i] & kStick) ? 1 : 0);
  }
  EXPECT_EQ(rows, p);
}

TEST_F(OutputFiles, AnUnpublishedSetLeavesNothing) {
  // all or none: a set destroyed before publish() (a later output failed)
  // writes no file and leaves no temporary; an old file stays as it was
  const std::string dir = ::testing::TempDir() + "/unpublished";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/old.csv") << "old";
  {
    OutputSet out;
    write_contact_csv(out, dir + "/old.csv", *R_->problem, fields());
    write_text(out, dir + "/new.json", "{}");
  }
  EXPECT_EQ(slurp(dir + "/old.csv"), "old");
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    ++files;
    EXPECT_EQ(e.path().filename(), "old.csv");
  }
  EXPECT_EQ(files, 1);
}

TEST_F(OutputFiles, VtuHoldsTheSolversFieldsOnPositiveVolumeHexahedra) {
  const std::string path = ::testing::TempDir() + "tresca_out.vtu";
  OutputSet out;
  const std::string cpath = write_vtu(out, path, *R_->problem, R_->u_full, fields(), VtkFormat::ascii);
  out.publish();
  EXPECT_EQ(cpath, ::testing::TempDir() + "tresca_out_contact.vtu");
  const Problem& P = *R_->problem;
  const GridDims& g = P.grid;
  const index N = g.nodes(), p = P.contact_nodes();
  const std::string v = slurp(path);
  const auto pts = data_array(v, "", "<Points>");
  const auto conn = data_array(v, "connectivity");
  const auto disp = data_array(v, "displacement");
  const auto force = data_array(v, "contact_force");
  const auto code = data_array(v, "contact_status");
  ASSERT_EQ(index(pts.size()), 3 * N);
  ASSERT_EQ(index(conn.size()), 8 * g.ex * g.ey * g.ez);
  ASSERT_EQ(index(disp.size()), 3 * N);
  ASSERT_EQ(index(code.size()), N);
  // every hexahedron, in VTK's node order, has the brick's volume (Jacobian at its centre)
  const double vol = g.hx() * g.hy() * g.hz();
  for (size_t c = 0; c < conn.size() / 8; ++c) {
    std::array<std::array<double, 3>, 8> q;
    for (int k = 0; k < 8; ++k)
      for (int a = 0; a < 3; ++a) q[k][a] = pts[3 * size_t(conn[8 * c + k]) + a];
    double J[3][3];
    for (int a = 0; a < 3; ++a) {
      J[0][a] = (q[1][a] - q[0][a] + q[2][a] - q[3][a] + q[5][a] - q[4][a] + q[6][a] - q[7][a]) / 4;
      J[1][a] = (q[3][a] - q[0][a] + q[2][a] - q[1][a] + q[7][a] - q[4][a] + q[6][a] - q[5][a]) / 4;
      J[2][a] = (q[4][a] - q[0][a] + q[5][a] - q[1][a] + q[6][a] - q[2][a] + q[7][a] - q[3][a]) / 4;
    }
    const double det = J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
                       J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
                       J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
    ASSERT_NEAR(det, vol, 1e-6 * vol) << "cell " << c;
  }
  // point data: displacement components of every node, contact values on the contact nodes
  std::vector<index> cid(N, -1);
  for (index i = 0; i < p; ++i) cid[P.contact_grid_node(i)] = i;
  const double us = 1e-11 * std::max(std::abs(R_->report.ux_min), 1e-3);
  for (index n = 0; n < N; ++n) {
    for (int a = 0; a < 3; ++a) ASSERT_NEAR(disp[3 * n + a], R_->u_full[a * N + n], us) << "node " << n << " comp " << a;
    const index i = cid[n];
    EXPECT_EQ(code[n], i < 0 ? 0 : status_code(R_->report.status[i])) << "node " << n;
    if (i >= 0) {
      const double fs = 1e-11 * std::abs(R_->report.lambda_sum);
      EXPECT_NEAR(force[3 * n], R_->report.r[i], fs);
      EXPECT_NEAR(force[3 * n + 1], R_->report.r[p + i], fs);
      EXPECT_NEAR(force[3 * n + 2], R_->newton.lambda[i], fs);
    }
  }
  // the contact face: quads over the bottom plane with the same values
  const std::string vc = slurp(cpath);
  const auto cd = data_array(vc, "displacement");
  const auto cf = data_array(vc, "contact_force");
  const auto cp = data_array(vc, "contact_pressure");
  const auto cc = data_array(vc, "contact_status");
  const index M = g.nx() * g.ny();
  ASSERT_EQ(index(cd.size()), 3 * M);
  ASSERT_EQ(index(cf.size()), 3 * M);
  ASSERT_EQ(index(cp.size()), M);
  double pressure_times_area = 0;
  for (index n = 0; n < M; ++n) {
    for (int a = 0; a < 3; ++a) ASSERT_NEAR(cd[3 * n + a], R_->u_full[a * N + n], us);
    const double lambda = cid[n] < 0 ? 0.0 : R_->newton.lambda[cid[n]];
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(cf[3 * n + a], force[3 * n + a], 1e-11 * std::abs(R_->report.lambda_sum));
    EXPECT_NEAR(cf[3 * n + 2], lambda, 1e-11 * std::abs(R_->report.lambda_sum));
    EXPECT_EQ(cc[n], cid[n] < 0 ? 0 : status_code(R_->report.status[cid[n]]));
    // the node's share of the face: a quarter of each quad it is a corner of
    const index ix = n % g.nx(), iy = n / g.nx();
    const double share = (ix == 0 || ix == g.ex ? 0.5 : 1) * (iy == 0 || iy == g.ey ? 0.5 : 1) * g.hx() * g.hy();
    EXPECT_NEAR(cp[n] * share, lambda, 1e-11 * std::abs(R_->report.lambda_sum)) << "node " << n;
    pressure_times_area += cp[n] * share;
  }
  EXPECT_NEAR(pressure_times_area, R_->report.lambda_sum, 1e-10 * std::abs(R_->report.lambda_sum));
  // its quads: each the face's element, its corners in order around it
  // (a bow-tie has signed area 0), all facing the same way, tiling the face
  const auto fp = data_array(vc, "", "<Points>");
  const auto fconn = data_array(vc, "connectivity");
  ASSERT_EQ(index(fp.size()), 3 * M);
  ASSERT_EQ(index(fconn.size()), 4 * g.ex * g.ey);
  double total = 0;
  for (size_t c = 0; c < fconn.size() / 4; ++c) {
    double area = 0;  // shoelace in the xy plane
    for (int k = 0; k < 4; ++k) {
      const size_t a = size_t(fconn[4 * c + k]), b = size_t(fconn[4 * c + (k + 1) % 4]);
      ASSERT_NEAR(fp[3 * a + 2], P.grid.z0, 1e-12) << "quad " << c << " leaves the contact plane";
      area += 0.5 * (fp[3 * a] * fp[3 * b + 1] - fp[3 * b] * fp[3 * a + 1]);
    }
    ASSERT_NEAR(area, g.hx() * g.hy(), 1e-9 * g.hx() * g.hy()) << "quad " << c;
    total += area;
  }
  EXPECT_NEAR(total, g.ex * g.hx() * g.ey * g.hy(), 1e-9);
}

TEST_F(OutputFiles, JsonSummaryRepeatsTheSolution) {
  RunOptions o;
  // the file's text, parsed back
  const Json j = Json::parse(json_text(run_summary(*spec_, *R_, 2, o)));
  const auto &u = R_->newton.u, &lam = R_->newton.lambda;
  const index p = R_->problem->contact_nodes();
  double lsum = 0, ux_min = INFINITY, uz_max = -INFINITY;
  for (index i = 0; i < p; ++i) {
    lsum += lam[i];
    ux_min = std::min(ux_min, u[i]);
    uz_max = std::max(uz_max, u[2 * p + i]);
  }
  EXPECT_NEAR(j["contact"]["lambda_sum"].get<double>(), lsum, 1e-12 * lsum);
  EXPECT_EQ(j["contact"]["ux_min"].get<double>(), ux_min);
  EXPECT_EQ(j["contact"]["uz_max"].get<double>(), uz_max);
  EXPECT_EQ(j["newton_iterations"].get<double>(), R_->newton.iterations);
  EXPECT_EQ(j["contact_nodes"].get<double>(), p);
  // separation first: stick and slip count nodes in contact only
  index active = 0, sticking = 0;
  for (index i = 0; i < p; ++i) {
    const bool contact = R_->report.status[i] & kContact;
    active += contact ? 1 : 0;
    sticking += contact && (R_->report.status[i] & kStick) ? 1 : 0;
  }
  EXPECT_EQ(j["contact"]["active"].get<double>(), active);
  EXPECT_EQ(j["contact"]["separated"].get<double>(), p - active);
  EXPECT_EQ(j["contact"]["sticking"].get<double>(), sticking);
  EXPECT_EQ(j["contact"]["sliding"].get<double>(), active - sticking);
  EXPECT_EQ(j["final_residual"].get<double>(), R_->newton.history.back());
}

}  // namespace tresca
