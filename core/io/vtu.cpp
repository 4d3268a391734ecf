#include "core/io/vtu.hpp"

#include <lzma.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "core/contact/nested.hpp"
#include "kernels/contact_maps.hpp"
#include "kernels/element.hpp"

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the VTU writer declares byte_order=\"LittleEndian\"");

namespace tresca {

VtkFormat parse_vtk_format(const std::string& s, const std::string& option) {
  if (s == "binary") return VtkFormat::binary;
  if (s == "ascii") return VtkFormat::ascii;
  throw std::invalid_argument(option + " '" + s + "' must be binary or ascii");
}

std::string vtu_step_name(const std::string& vtu_path, const std::string& suffix) {
  return path_stem(vtu_path) + suffix + ".vtu";
}
std::string pvd_name(const std::string& vtu_path) { return path_stem(vtu_path) + ".pvd"; }

namespace {

// One DataArray: its values as little-endian bytes of `type`.
struct Array {
  enum class Type { f64, f32, i32, i64, u8 } type;
  std::string name;  // empty: the Points array
  int components;
  std::vector<unsigned char> bytes;

  template <class T>
  Array(Type t, std::string n, int comps, const std::vector<T>& v)
      : type(t), name(std::move(n)), components(comps), bytes(v.size() * sizeof(T)) {
    if (!v.empty()) std::memcpy(bytes.data(), v.data(), bytes.size());
  }
  const char* type_name() const {
    switch (type) {
      case Type::f64: return "Float64";
      case Type::f32: return "Float32";
      case Type::i32: return "Int32";
      case Type::i64: return "Int64";
      default: return "UInt8";
    }
  }
  size_t size() const {
    return bytes.size() / (type == Type::f64 || type == Type::i64 ? 8 : type == Type::i32 || type == Type::f32 ? 4 : 1);
  }
  void write_ascii(std::FILE* f) const {
    const size_t n = size();
    for (size_t i = 0; i < n; ++i) {
      const char sep = (i + 1) % components ? ' ' : '\n';
      switch (type) {
        case Type::f64: {
          double x;
          std::memcpy(&x, &bytes[8 * i], 8);
          std::fprintf(f, "%.12g%c", x, sep);
          break;
        }
        case Type::f32: {  // 9 digits: the float exactly
          float x;
          std::memcpy(&x, &bytes[4 * i], 4);
          std::fprintf(f, "%.9g%c", double(x), sep);
          break;
        }
        case Type::i32: {
          std::int32_t x;
          std::memcpy(&x, &bytes[4 * i], 4);
          std::fprintf(f, "%d%c", int(x), sep);
          break;
        }
        case Type::i64: {
          std::int64_t x;
          std::memcpy(&x, &bytes[8 * i], 8);
          std::fprintf(f, "%lld%c", (long long)x, sep);
          break;
        }
        default: std::fprintf(f, "%d%c", int(bytes[i]), sep);
      }
    }
  }
};

// VTK's compressed layout of one array: UInt64 header, then the blocks,
// each an .xz stream (vtkLZMADataCompressor). LZMA, not zlib: about twice
// zlib's ratio on the body for a little more time (perf/RESULTS.md §0f).
// 1 MiB blocks, compressed in parallel.
constexpr size_t kBlock = size_t(1) << 20;
constexpr std::uint32_t kLzmaPreset = 1;

std::vector<unsigned char> compressed(const std::vector<unsigned char>& raw) {
  const size_t nb = (raw.size() + kBlock - 1) / kBlock;
  std::vector<std::vector<unsigned char>> blocks(nb);
  bool ok = true;
#pragma omp parallel for schedule(dynamic) reduction(&& : ok)
  for (long long b = 0; b < (long long)nb; ++b) {
    const size_t at = size_t(b) * kBlock, len = std::min(kBlock, raw.size() - at);
    size_t out = 0;
    blocks[b].resize(lzma_stream_buffer_bound(len));
    ok = lzma_easy_buffer_encode(kLzmaPreset, LZMA_CHECK_CRC32, nullptr, &raw[at], len, blocks[b].data(), &out,
                                 blocks[b].size()) == LZMA_OK && ok;
    blocks[b].resize(out);
  }
  if (!ok) throw std::runtime_error("LZMA compression failed");
  std::vector<std::uint64_t> head{nb, kBlock, raw.size() % kBlock};
  for (const auto& b : blocks) head.push_back(b.size());
  std::vector<unsigned char> blob(head.size() * 8);
  std::memcpy(blob.data(), head.data(), blob.size());
  for (const auto& b : blocks) blob.insert(blob.end(), b.begin(), b.end());
  return blob;
}

// What the arrays mean, in every file (an XML comment: readers skip it).
const char* kLegend =
    "<!-- tresca: SI units (m, N, Pa); the mesh is the undeformed body (ParaView: Warp By Vector with\n"
    "     displacement draws it deformed). Point data: displacement [m]; contact_force [N], the nodal\n"
    "     force of the contact on a contact node (x, y: friction; z: the normal force lambda), 0 elsewhere;\n"
    "     contact_pressure [Pa], lambda over the node's share of the contact face's area;\n"
    "     contact_status: 0 not a contact node (the clamped edge x = x0 or off the face), 1 separated,\n"
    "     2 stick, 3 slip. Cell data (body): stress [Pa], the Cauchy stress at the cell's centre (xx, yy,\n"
    "     zz, xy, yz, xz; single precision); von_mises [Pa]. See docs/outputs.md. -->\n";

// One piece of an unstructured grid: points, cells of one VTK type, point data.
struct Piece {
  index points = 0, cells = 0;
  std::vector<Array> geometry;    // Points
  std::vector<Array> topology;    // Cells: connectivity, offsets, types
  std::vector<Array> point_data;  // the first one is the vector field shown
  std::vector<Array> cell_data;   // the first one is the tensor shown, the second the scalar

  Piece(const std::vector<double>& xyz, const std::vector<index>& conn, int per_cell, std::uint8_t vtk_type)
      : points(index(xyz.size() / 3)), cells(index(conn.size()) / per_cell) {
    geometry.emplace_back(Array::Type::f64, "", 3, xyz);
    std::vector<index> offsets(cells);
    for (index c = 0; c < cells; ++c) offsets[c] = per_cell * (c + 1);
    if (index(conn.size()) < (index(1) << 31)) {  // Int32 while it fits: half the bytes
      topology.emplace_back(Array::Type::i32, "connectivity", 1, std::vector<std::int32_t>(conn.begin(), conn.end()));
      topology.emplace_back(Array::Type::i32, "offsets", 1, std::vector<std::int32_t>(offsets.begin(), offsets.end()));
    } else {
      topology.emplace_back(Array::Type::i64, "connectivity", 1, std::vector<std::int64_t>(conn.begin(), conn.end()));
      topology.emplace_back(Array::Type::i64, "offsets", 1, std::vector<std::int64_t>(offsets.begin(), offsets.end()));
    }
    topology.emplace_back(Array::Type::u8, "types", 1, std::vector<std::uint8_t>(size_t(cells), vtk_type));
  }

  void write(std::FILE* f, VtkFormat format) const {
    const bool bin = format == VtkFormat::binary;
    std::fprintf(f,
                 "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
                 "byte_order=\"LittleEndian\" header_type=\"UInt64\"%s>\n<UnstructuredGrid>\n<Piece "
                 "NumberOfPoints=\"%lld\" NumberOfCells=\"%lld\">\n",
                 bin ? " compressor=\"vtkLZMADataCompressor\"" : "", (long long)points, (long long)cells);
    std::fputs(kLegend, f);
    std::vector<std::vector<unsigned char>> blobs;
    std::uint64_t offset = 0;
    auto section = [&](const char* tag, const std::vector<Array>& arrays, const char* attrs) {
      std::fprintf(f, "<%s%s>\n", tag, attrs);
      for (const Array& a : arrays) {
        std::fprintf(f, "<DataArray type=\"%s\"", a.type_name());
        if (!a.name.empty()) std::fprintf(f, " Name=\"%s\"", a.name.c_str());
        if (a.components > 1) std::fprintf(f, " NumberOfComponents=\"%d\"", a.components);
        if (bin) {
          blobs.push_back(compressed(a.bytes));
          std::fprintf(f, " format=\"appended\" offset=\"%llu\"/>\n", (unsigned long long)offset);
          offset += blobs.back().size();
        } else {
          std::fprintf(f, " format=\"ascii\">\n");
          a.write_ascii(f);
          std::fprintf(f, "</DataArray>\n");
        }
      }
      std::fprintf(f, "</%s>\n", tag);
    };
    section("Points", geometry, "");
    section("Cells", topology, "");
    const std::string shown = " Vectors=\"" + point_data.front().name + "\"";
    section("PointData", point_data, shown.c_str());
    if (!cell_data.empty()) {
      const std::string cshown = " Tensors=\"" + cell_data[0].name + "\" Scalars=\"" + cell_data[1].name + "\"";
      section("CellData", cell_data, cshown.c_str());
    }
    std::fprintf(f, "</Piece>\n</UnstructuredGrid>\n");
    if (bin) {
      std::fprintf(f, "<AppendedData encoding=\"raw\">\n_");
      for (const auto& b : blobs) std::fwrite(b.data(), 1, b.size(), f);
      std::fprintf(f, "\n</AppendedData>\n");
    }
    std::fprintf(f, "</VTKFile>\n");
  }
};

// contact_status: 0 clamped (x = 0), 1 separated, 2 stick, 3 slip (contact_state)
int status_code(std::uint8_t s) { return 1 + int(contact_state(s)); }

}  // namespace

namespace {

// the per-node contact id of the bottom plane (-1: not a contact node)
std::vector<index> contact_ids(const Problem& P) {
  const GridDims& g = P.grid;
  std::vector<index> cid(g.nx() * g.ny(), -1);
  for (index i = 0; i < P.contact_nodes(); ++i) cid[P.contact_grid_node(i)] = i;
  return cid;
}

// The body's hexahedra between global node rows [r0, r1) (all of x and z),
// displacement from the SoA vector u on grid ub, whose row 0 is global row rb.
void write_body(OutputSet& out, const std::string& path, const Problem& P, index r0, index r1, const real* u,
                const GridDims& ub, index rb, const ContactFields& c, VtkFormat format) {
  const GridDims& g = P.grid;
  const index p = P.contact_nodes(), nx = g.nx(), rows = r1 - r0, n_pts = nx * rows * g.nz(), Nu = ub.nodes();
  const std::vector<index> cid = contact_ids(P);
  auto local = [&](index ix, index iy, index iz) { return ix + nx * ((iy - r0) + rows * iz); };
  std::vector<double> xyz(3 * size_t(n_pts)), disp(3 * size_t(n_pts)), force(3 * size_t(n_pts), 0.0),
      pressure(size_t(n_pts), 0.0);
  std::vector<std::uint8_t> code(n_pts, 0);
  for (index iz = 0; iz < g.nz(); ++iz)
    for (index iy = r0; iy < r1; ++iy)
      for (index ix = 0; ix < nx; ++ix) {
        const index n = local(ix, iy, iz), m = ub.node(ix, iy - rb, iz);
        xyz[3 * n] = g.x0 + ix * g.hx();
        xyz[3 * n + 1] = g.y0 + iy * g.hy();
        xyz[3 * n + 2] = g.z0 + iz * g.hz();
        for (int a = 0; a < 3; ++a) disp[3 * n + a] = u[a * Nu + m];
        if (iz == 0)
          if (const index i = cid[ix + nx * iy]; i >= 0) {
            force[3 * n] = (*c.r)[i];
            force[3 * n + 1] = (*c.r)[p + i];
            force[3 * n + 2] = (*c.lambda)[i];
            pressure[n] = (*c.lambda)[i] / contact_area(g, i);
            code[n] = std::uint8_t(status_code((*c.status)[i]));
          }
      }
  const index n_cells = g.ex * (rows - 1) * g.ez;
  std::vector<index> conn;
  conn.reserve(size_t(8 * n_cells));
  // derived fields in single precision: 7 digits are more than a stress
  // plot resolves, and noisy doubles are the slowest data to compress
  std::vector<float> stress(6 * size_t(n_cells)), mises(static_cast<size_t>(n_cells));
  const int order[8] = {0, 1, 3, 2, 4, 5, 7, 6};  // VTK_HEXAHEDRON node order
  index cell = 0;
  for (index ez = 0; ez < g.ez; ++ez)
    for (index ey = r0; ey + 1 < r1; ++ey)
      for (index ex = 0; ex < g.ex; ++ex, ++cell) {
        for (int k : order) conn.push_back(local(ex + (k & 1), ey + ((k >> 1) & 1), ez + ((k >> 2) & 1)));
        real ue[24];
        for (int L = 0; L < 8; ++L) {
          const index m = ub.node(ex + (L & 1), ey + ((L >> 1) & 1) - rb, ez + ((L >> 2) & 1));
          for (int a = 0; a < 3; ++a) ue[3 * L + a] = u[a * Nu + m];
        }
        real s[6];
        centroid_stress(g.hx(), g.hy(), g.hz(), P.spec.E, P.spec.nu, ue, s);
        for (int k = 0; k < 6; ++k) stress[6 * cell + k] = float(s[k]);
        mises[cell] = float(von_mises(s));
      }
  Piece body(xyz, conn, 8, 12);
  body.point_data.emplace_back(Array::Type::f64, "displacement", 3, disp);
  body.point_data.emplace_back(Array::Type::f64, "contact_force", 3, force);
  body.point_data.emplace_back(Array::Type::f64, "contact_pressure", 1, pressure);
  body.point_data.emplace_back(Array::Type::u8, "contact_status", 1, code);
  body.cell_data.emplace_back(Array::Type::f32, "stress", 6, stress);
  body.cell_data.emplace_back(Array::Type::f32, "von_mises", 1, mises);
  body.write(out.create(path), format);
}

// The contact face (the bottom plane as quads, its own point numbering),
// from the contact vectors: u there is u_c, and 0 on the clamped x = 0 nodes.
void write_face(OutputSet& out, const std::string& path, const Problem& P, const ContactFields& c, VtkFormat format) {
  const GridDims& g = P.grid;
  const index M = g.nx() * g.ny(), p = P.contact_nodes();
  const std::vector<index> cid = contact_ids(P);
  std::vector<double> xyz(3 * size_t(M)), disp(3 * size_t(M), 0.0), force(3 * size_t(M), 0.0), pressure(M, 0.0);
  std::vector<std::uint8_t> code(M, 0);
  for (index n = 0; n < M; ++n) {
    xyz[3 * n] = g.x0 + (n % g.nx()) * g.hx();
    xyz[3 * n + 1] = g.y0 + (n / g.nx()) * g.hy();
    xyz[3 * n + 2] = g.z0;
    if (const index i = cid[n]; i >= 0) {
      for (int a = 0; a < 3; ++a) disp[3 * n + a] = (*c.u)[a * p + i];
      force[3 * n] = (*c.r)[i];
      force[3 * n + 1] = (*c.r)[p + i];
      force[3 * n + 2] = (*c.lambda)[i];
      pressure[n] = (*c.lambda)[i] / contact_area(g, i);
      code[n] = std::uint8_t(status_code((*c.status)[i]));
    }
  }
  std::vector<index> conn;
  for (index ey = 0; ey < g.ey; ++ey)
    for (index ex = 0; ex < g.ex; ++ex)
      for (index k : {index(0), index(1), g.nx() + 1, g.nx()}) conn.push_back(ex + g.nx() * ey + k);
  Piece face(xyz, conn, 4, 9);
  face.point_data.emplace_back(Array::Type::f64, "displacement", 3, disp);
  face.point_data.emplace_back(Array::Type::f64, "contact_force", 3, force);
  face.point_data.emplace_back(Array::Type::f64, "contact_pressure", 1, pressure);
  face.point_data.emplace_back(Array::Type::u8, "contact_status", 1, code);
  face.write(out.create(path), format);
}

}  // namespace

std::string write_vtu(OutputSet& out, const std::string& path, const Problem& P, const Field<real>& u_full,
                      const ContactFields& c, VtkFormat format) {
  write_body(out, path, P, 0, P.grid.ny(), u_full.data(), P.grid, 0, c, format);
  const std::string cpath = vtu_companion(path);
  write_face(out, cpath, P, c, format);
  return cpath;
}

std::string pvtu_piece_name(const std::string& path, int rank) {
  return path_stem(path) + "_p" + std::to_string(rank) + ".vtu";
}

std::string write_pvtu(OutputSet& out, const std::string& path, const Problem& P, const Slab& s,
                       const Field<real>& u_local, const ContactFields& c, VtkFormat format) {
  // this rank's rows and the ghost row above: the cells between two slabs are the lower one's
  write_body(out, pvtu_piece_name(path, s.rank), P, s.y_begin, s.y_end + s.hi, u_local.data(), s.local,
             s.y_begin - s.lo, c, format);
  if (s.rank != 0) return "";
  std::string x =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n<PUnstructuredGrid GhostLevel=\"0\">\n<PPointData Vectors=\"displacement\">\n"
      "<PDataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\"/>\n"
      "<PDataArray type=\"Float64\" Name=\"contact_force\" NumberOfComponents=\"3\"/>\n"
      "<PDataArray type=\"Float64\" Name=\"contact_pressure\" NumberOfComponents=\"1\"/>\n"
      "<PDataArray type=\"UInt8\" Name=\"contact_status\" NumberOfComponents=\"1\"/>\n</PPointData>\n"
      "<PCellData Tensors=\"stress\" Scalars=\"von_mises\">\n"
      "<PDataArray type=\"Float32\" Name=\"stress\" NumberOfComponents=\"6\"/>\n"
      "<PDataArray type=\"Float32\" Name=\"von_mises\" NumberOfComponents=\"1\"/>\n</PCellData>\n"
      "<PPoints>\n<PDataArray type=\"Float64\" NumberOfComponents=\"3\"/>\n</PPoints>\n";
  for (int q = 0; q < s.ranks; ++q) {
    std::string f = pvtu_piece_name(path, q);
    if (const auto slash = f.find_last_of('/'); slash != std::string::npos) f = f.substr(slash + 1);
    x += "<Piece Source=\"" + xml_escaped(f) + "\"/>\n";
  }
  write_text(out, path_stem(path) + ".pvtu", x + "</PUnstructuredGrid>\n</VTKFile>\n");
  const std::string cpath = vtu_companion(path);
  write_face(out, cpath, P, c, format);
  return cpath;
}

void write_pvd(OutputSet& out, const std::string& path, const std::vector<PvdStep>& steps) {
  const auto slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  std::string s = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n";
  for (const PvdStep& st : steps)
    for (size_t part = 0; part < st.files.size(); ++part) {
      std::string f = st.files[part];
      if (!dir.empty() && f.compare(0, dir.size(), dir) == 0) f = f.substr(dir.size());
      char head[96];
      std::snprintf(head, sizeof head, "<DataSet timestep=\"%.17g\" group=\"\" part=\"%zu\" file=\"", st.time, part);
      s += head + xml_escaped(f) + "\"/>\n";
    }
  write_text(out, path, s + "</Collection>\n</VTKFile>\n");
}

}  // namespace tresca
