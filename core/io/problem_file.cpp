#include "core/io/problem_file.hpp"

#include "core/io/output.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace tresca {

namespace {

using nlohmann::json;

class Reader {
 public:
  explicit Reader(std::string origin) : origin_(std::move(origin)) {}
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw std::invalid_argument(origin_ + ": " + (key.empty() ? "" : "'" + key + "' ") + what);
  }
  // j must be an object whose keys are all in `allowed`
  void object(const json& j, const std::string& key, std::set<std::string> allowed) const {
    if (!j.is_object()) fail(key, "must be an object");
    for (auto it = j.begin(); it != j.end(); ++it)
      if (!allowed.count(it.key())) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        fail(key.empty() ? it.key() : key + "." + it.key(), "is not a known key (known here: " + list + ")");
      }
  }
  real number(const json& j, const std::string& key) const {
    if (!j.is_number()) fail(key, "must be a number");
    return j.get<real>();
  }
  long long integer(const json& j, const std::string& key) const {
    if (!j.is_number_integer()) fail(key, "must be an integer");
    return j.get<long long>();
  }
  template <size_t N>
  std::array<real, N> numbers(const json& j, const std::string& key) const {
    if (!j.is_array() || j.size() != N) fail(key, "must be an array of " + std::to_string(N) + " numbers");
    std::array<real, N> v{};
    for (size_t i = 0; i < N; ++i) v[i] = number(j[i], key + "[" + std::to_string(i) + "]");
    return v;
  }

 private:
  std::string origin_;
};

}  // namespace

ProblemFile parse_problem(const std::string& text, const std::string& origin) {
  const Reader r(origin);
  json j;
  // a key given twice in one object: JSON keeps the last, which would
  // silently drop the first (the parser's callback sees each key as read)
  std::vector<std::set<std::string>> keys;  // of the objects open now
  std::vector<std::string> path;            // their keys
  std::string twice;
  const json::parser_callback_t note_keys = [&](int, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) {
      keys.emplace_back();
    } else if (event == json::parse_event_t::object_end) {
      keys.pop_back();
    } else if (event == json::parse_event_t::key) {
      const std::string k = parsed.get<std::string>();
      path.resize(keys.size() - 1);
      path.push_back(k);
      if (!keys.back().insert(k).second && twice.empty())
        for (const std::string& p : path) twice += (twice.empty() ? "" : ".") + p;
    }
    return true;
  };
  try {
    j = json::parse(text, note_keys, true, /*ignore_comments=*/true);
  } catch (const json::parse_error& e) {
    r.fail("", std::string("is not valid JSON: ") + e.what());
  }
  if (!twice.empty()) r.fail(twice, "is given twice (JSON would keep the last silently)");
  // a run summary (tresca --json): its "problem" object, the rest ignored
  if (j.is_object() && j.contains("residual_history") && j.contains("problem") && j["problem"].is_object()) {
    const json inner = j["problem"];
    j = inner;
  }
  r.object(j, "", {"mesh", "box", "material", "loads", "friction", "obstacle"});
  ProblemFile f;
  ProblemSpec& s = f.spec;
  if (j.contains("mesh")) {
    const json& m = j["mesh"];
    r.object(m, "mesh", {"level", "dims"});
    if (m.contains("level") == m.contains("dims")) r.fail("mesh", "needs exactly one of 'level' and 'dims'");
    if (m.contains("level")) {
      const long long L = r.integer(m["level"], "mesh.level");
      try {
        s = spec_for_level(L);
      } catch (const std::invalid_argument& e) {
        r.fail("mesh.level", e.what());
      }
    } else {
      const json& d = m["dims"];
      if (!d.is_array() || d.size() != 3) r.fail("mesh.dims", "must be an array of 3 element counts");
      index e[3];
      for (int a = 0; a < 3; ++a) {
        e[a] = r.integer(d[a], "mesh.dims[" + std::to_string(a) + "]");
        if (e[a] < 1) r.fail("mesh.dims[" + std::to_string(a) + "]", "must be >= 1");
      }
      s = spec_for_dims(e[0], e[1], e[2]);
    }
    f.mesh_given = true;
  }
  if (j.contains("box")) {
    const json& b = j["box"];
    r.object(b, "box", {"lengths", "origin"});
    if (b.contains("lengths")) {
      const auto L = r.numbers<3>(b["lengths"], "box.lengths");
      for (int a = 0; a < 3; ++a)
        if (!(L[a] > 0)) r.fail("box.lengths", "must be positive");
      s.lx = L[0], s.ly = L[1], s.lz = L[2];
    }
    if (b.contains("origin")) {
      const auto o = r.numbers<3>(b["origin"], "box.origin");
      s.x0 = o[0], s.y0 = o[1], s.z0 = o[2];
    }
  }
  if (j.contains("material")) {
    const json& m = j["material"];
    r.object(m, "material", {"E", "nu"});
    if (m.contains("E")) s.E = r.number(m["E"], "material.E");
    if (m.contains("nu")) s.nu = r.number(m["nu"], "material.nu");
  }
  if (j.contains("loads")) {
    const json& l = j["loads"];
    r.object(l, "loads", {"traction", "body_force", "scale"});
    if (l.contains("traction")) {
      const json& t = l["traction"];
      r.object(t, "loads.traction", {"x1", "y0", "y1", "z1"});
      for (int fc = 0; fc < kLoadFaces; ++fc) {
        const std::string name = load_face_name(fc);
        s.traction[fc] = t.contains(name) ? r.numbers<3>(t[name], "loads.traction." + name) : std::array<real, 3>{0, 0, 0};
      }
    }
    if (l.contains("body_force")) s.body_force = r.numbers<3>(l["body_force"], "loads.body_force");
    if (l.contains("scale")) s.load_scale = r.number(l["scale"], "loads.scale");
  }
  if (j.contains("friction")) {
    const json& fr = j["friction"];
    r.object(fr, "friction", {"tresca", "coulomb"});
    if (fr.contains("tresca") == fr.contains("coulomb")) r.fail("friction", "needs exactly one of 'tresca' and 'coulomb'");
    if (fr.contains("tresca")) s.phi = r.number(fr["tresca"], "friction.tresca");
    if (fr.contains("coulomb")) {
      const real F = r.number(fr["coulomb"], "friction.coulomb");
      if (!(F >= 0)) r.fail("friction.coulomb", "must be >= 0");
      f.friction = coulomb_friction(F);
    }
  }
  if (j.contains("obstacle")) {
    const json& o = j["obstacle"];
    if (!o.is_object() || !o.contains("kind") || !o["kind"].is_string())
      r.fail("obstacle", "needs a 'kind' (plane, sphere or cylinder)");
    const std::string kind = o["kind"].get<std::string>();
    Obstacle& ob = s.obstacle;
    ob = Obstacle{};
    if (kind == "plane") {
      r.object(o, "obstacle", {"kind", "gap", "slope"});
      if (o.contains("slope")) {
        const auto sl = r.numbers<2>(o["slope"], "obstacle.slope");
        ob.slope_x = sl[0], ob.slope_y = sl[1];
      }
    } else if (kind == "sphere") {
      r.object(o, "obstacle", {"kind", "gap", "radius", "center"});
      ob.kind = Obstacle::Kind::sphere;
      if (!o.contains("radius") || !o.contains("center")) r.fail("obstacle", "a sphere needs 'radius' and 'center'");
      ob.radius = r.number(o["radius"], "obstacle.radius");
      const auto c = r.numbers<2>(o["center"], "obstacle.center");
      ob.cx = c[0], ob.cy = c[1];
    } else if (kind == "cylinder") {
      r.object(o, "obstacle", {"kind", "gap", "radius", "y"});
      ob.kind = Obstacle::Kind::cylinder;
      if (!o.contains("radius") || !o.contains("y")) r.fail("obstacle", "a cylinder needs 'radius' and 'y'");
      ob.radius = r.number(o["radius"], "obstacle.radius");
      ob.cy = r.number(o["y"], "obstacle.y");
    } else {
      r.fail("obstacle.kind", "'" + kind + "' is not plane, sphere or cylinder");
    }
    if (o.contains("gap")) ob.gap = r.number(o["gap"], "obstacle.gap");
  }
  try {
    ProblemSpec t = s;  // without a mesh the command line or the default level gives one later
    if (!f.mesh_given) t.ex = t.ey = t.ez = 1;
    validate(t);
  } catch (const std::invalid_argument& e) {
    r.fail("", e.what());
  }
  return f;
}

ProblemFile read_problem_file(const std::string& path) {
  return parse_problem(read_text_file(path, "problem file"), "problem file '" + path + "'");
}

std::vector<std::vector<real>> read_contact_csv(const std::string& path, const GridDims& g,
                                                const std::vector<std::string>& columns, const std::string& what) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument("cannot read " + what + " '" + path + "'");
  auto fail = [&](long line, const std::string& why) {
    throw std::invalid_argument(what + " '" + path + "' line " + std::to_string(line) + ": " + why);
  };
  auto fields = [](std::string row) {
    if (!row.empty() && row.back() == '\r') row.pop_back();
    std::vector<std::string> f;
    std::istringstream is(row);
    for (std::string x; std::getline(is, x, ',');) f.push_back(x);
    if (!row.empty() && row.back() == ',') f.push_back("");
    return f;
  };
  std::string row;
  std::vector<std::string> want{"ix", "iy"};
  want.insert(want.end(), columns.begin(), columns.end());
  std::string header_names;
  for (const auto& w : want) header_names += (header_names.empty() ? "" : ",") + w;
  if (!std::getline(in, row)) fail(1, "empty; the header must name " + header_names);
  const std::vector<std::string> head = fields(row);
  std::vector<size_t> col(want.size());
  for (size_t k = 0; k < want.size(); ++k) {
    const auto it = std::find(head.begin(), head.end(), want[k]);
    if (it == head.end()) fail(1, "the header has no column '" + want[k] + "' (it must name " + header_names + ")");
    col[k] = size_t(it - head.begin());
  }
  const index p = g.ex * g.ny();
  std::vector<std::vector<real>> out(columns.size(), std::vector<real>(p));
  std::vector<char> seen(p, 0);
  index count = 0;
  for (long line = 2; std::getline(in, row); ++line) {
    if (row.empty() || row == "\r") continue;
    const std::vector<std::string> f = fields(row);
    if (f.size() != head.size())
      fail(line, "has " + std::to_string(f.size()) + " fields, the header " + std::to_string(head.size()));
    std::vector<double> v(want.size());
    for (size_t k = 0; k < want.size(); ++k) {
      const std::string& x = f[col[k]];
      char* end = nullptr;
      errno = 0;
      v[k] = std::strtod(x.c_str(), &end);
      if (x.empty() || *end != '\0' || !std::isfinite(v[k]) || (errno == ERANGE && std::abs(v[k]) > 1))
        fail(line, want[k] + " '" + x.substr(0, 40) + "' is not a finite number");
    }
    if (v[0] != std::floor(v[0]) || v[1] != std::floor(v[1]) || v[0] < 1 || v[0] > g.ex || v[1] < 0 || v[1] > g.ey)
      fail(line, "node (" + f[col[0]] + ", " + f[col[1]] + ") is not a contact node of this mesh (1 <= ix <= " +
                     std::to_string(g.ex) + ", 0 <= iy <= " + std::to_string(g.ey) + ")");
    const index c = (index(v[0]) - 1) + g.ex * index(v[1]);
    if (seen[c]) fail(line, "node (" + f[col[0]] + ", " + f[col[1]] + ") is given twice");
    seen[c] = 1;
    ++count;
    for (size_t k = 0; k < columns.size(); ++k) out[k][c] = v[k + 2];
  }
  if (count != p)
    throw std::invalid_argument(what + " '" + path + "' gives " + std::to_string(count) + " of the " +
                                std::to_string(p) + " contact nodes of this mesh");
  return out;
}

std::vector<real> read_gap_csv(const std::string& path, const GridDims& g) {
  std::vector<real> gap = std::move(read_contact_csv(path, g, {"gap"}, "gap file")[0]);
  for (index c = 0; c < index(gap.size()); ++c)
    if (gap[c] < 0)
      throw std::invalid_argument("gap file '" + path + "': the gap at node (" + std::to_string(1 + c % g.ex) + ", " +
                                  std::to_string(c / g.ex) + ") is negative");
  return gap;
}

std::string problem_json(const ProblemSpec& s, const FrictionLaw& friction) {
  json j;
  j["mesh"] = json{{"dims", {s.ex, s.ey, s.ez}}};
  j["box"] = json{{"lengths", {s.lx, s.ly, s.lz}}, {"origin", {s.x0, s.y0, s.z0}}};
  j["material"] = json{{"E", s.E}, {"nu", s.nu}};
  json t = json::object();
  for (int f = 0; f < kLoadFaces; ++f)
    if (s.traction[f] != std::array<real, 3>{0, 0, 0}) t[load_face_name(f)] = s.traction[f];
  j["loads"] = json{{"traction", t}, {"body_force", s.body_force}, {"scale", s.load_scale}};
  j["friction"] = friction.is_coulomb() ? json{{"coulomb", friction.F}} : json{{"tresca", s.phi}};
  const Obstacle& o = s.obstacle;
  if (o.kind == Obstacle::Kind::plane)
    j["obstacle"] = json{{"kind", "plane"}, {"gap", o.gap}, {"slope", {o.slope_x, o.slope_y}}};
  else if (o.kind == Obstacle::Kind::sphere)
    j["obstacle"] = json{{"kind", "sphere"}, {"gap", o.gap}, {"radius", o.radius}, {"center", {o.cx, o.cy}}};
  else
    j["obstacle"] = json{{"kind", "cylinder"}, {"gap", o.gap}, {"radius", o.radius}, {"y", o.cy}};
  return j.dump();
}

}  // namespace tresca
