#include "core/io/output.hpp"

#include <filesystem>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <cstdlib>
#include <csignal>
#include <memory>

#include <sys/stat.h>
#include <unistd.h>
#include <stdexcept>

#include "kernels/contact_maps.hpp"

namespace tresca {

namespace {
// Temporaries alive right now, removed by SIGINT / SIGTERM / SIGHUP before
// the signal takes its default course (unlink is async-signal-safe).
constexpr int kMaxLive = 64;
char* g_live[kMaxLive];
volatile std::sig_atomic_t g_handlers_installed = 0;

extern "C" void remove_live_temporaries(int sig) {
  for (int i = 0; i < kMaxLive; ++i)
    if (g_live[i]) ::unlink(g_live[i]);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

void register_live(const std::string& tmp) {
  if (!g_handlers_installed) {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, remove_live_temporaries);
    g_handlers_installed = 1;
  }
  for (int i = 0; i < kMaxLive; ++i)
    if (!g_live[i]) {
      g_live[i] = ::strdup(tmp.c_str());
      return;
    }
}

void unregister_live(const std::string& tmp) {
  for (int i = 0; i < kMaxLive; ++i)
    if (g_live[i] && tmp == g_live[i]) {
      char* p = g_live[i];
      g_live[i] = nullptr;
      std::free(p);
      return;
    }
}

// What an output path is: refused (why), a special file (FIFO, device) to be
// written in place, or a regular file, existing or not, to be replaced
// through a temporary. One classification for the early check and the writer.
struct OutputTarget {
  std::string refused;  // non-empty: not writable as an output, and why
  bool special = false, exists = false;
  mode_t mode = 0;  // an existing file's permissions
};
OutputTarget output_target(const std::string& path) {
  OutputTarget t;
  if (path.empty() || path.back() == '/') {
    t.refused = "is not a file name";
    return t;
  }
  struct stat st;
  t.exists = ::stat(path.c_str(), &st) == 0;
  if (t.exists && S_ISDIR(st.st_mode)) t.refused = "is a directory";
  t.special = t.exists && !S_ISDIR(st.st_mode) && !S_ISREG(st.st_mode);
  if (t.exists) t.mode = st.st_mode & 07777;
  return t;
}

// a fresh temporary next to `path` (mkstemp: exclusive, never a symlink);
// its name in tmp, its descriptor returned, < 0 if it cannot be made
int make_temporary(const std::string& path, std::string& tmp) {
  tmp = path + ".XXXXXX";
  return ::mkstemp(&tmp[0]);
}

}  // namespace

// One output file, written safely (issue 11):
// - a path that exists and is not a regular file (a FIFO, /dev/null, a
//   terminal) is written in place: replacing it would destroy it;
// - otherwise the data go to a fresh temporary next to the target, created
//   exclusively by mkstemp (no fixed name to plant a symlink at, nobody's file
//   deleted), flushed to disk, given the replaced file's permissions (or the
//   umask's for a new file) and renamed over the target by publish(): the
//   file is complete or absent, never half-written;
// - a directory, or a path ending in '/', is refused.
class OutputFile {
 public:
  explicit OutputFile(const std::string& path) : path_(path) {
    const OutputTarget t = output_target(path);
    if (!t.refused.empty()) throw std::runtime_error("cannot write '" + path + "': it " + t.refused);
    if (t.special) {
      f_ = std::fopen(path.c_str(), "wb");
      if (!f_) throw std::runtime_error("cannot write '" + path + "'");
      return;
    }
    const int fd = make_temporary(path, tmp_);
    if (fd < 0) {
      tmp_.clear();
      throw std::runtime_error("cannot write '" + path + "'");
    }
    register_live(tmp_);
    mode_t mode = t.mode;
    if (!t.exists) {
      const mode_t mask = ::umask(0);
      ::umask(mask);
      mode = 0666 & ~mask;
    }
    ::fchmod(fd, mode);
    f_ = ::fdopen(fd, "wb");
    if (!f_) {
      ::close(fd);
      throw std::runtime_error("cannot write '" + path + "'");
    }
  }
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  ~OutputFile() {
    if (f_) std::fclose(f_);
    if (!tmp_.empty()) {  // not published: no debris
      ::unlink(tmp_.c_str());
      unregister_live(tmp_);
    }
  }
  std::FILE* get() const { return f_; }
  // all data on disk and the file closed; throws if any write failed
  void finish() {
    bool ok = std::fflush(f_) == 0 && !std::ferror(f_);
    if (ok && !tmp_.empty()) ok = ::fsync(::fileno(f_)) == 0;
    ok = std::fclose(f_) == 0 && ok;
    f_ = nullptr;
    if (!ok) throw std::runtime_error("error while writing '" + path_ + "'");
  }
  // the finished temporary becomes the file
  void publish() {
    if (tmp_.empty()) return;
    if (std::rename(tmp_.c_str(), path_.c_str()) != 0)
      throw std::runtime_error("cannot rename the temporary file to '" + path_ + "'");
    unregister_live(tmp_);
    tmp_.clear();
  }

 private:
  std::string path_, tmp_;
  std::FILE* f_ = nullptr;
};

OutputSet::OutputSet() = default;
OutputSet::~OutputSet() = default;  // unpublished files remove their temporaries

std::FILE* OutputSet::create(const std::string& path) {
  files_.push_back(std::make_unique<OutputFile>(path));
  return files_.back()->get();
}

void OutputSet::publish() {
  for (auto& f : files_) f->finish();  // every file complete on disk first
  for (auto& f : files_) f->publish();
  files_.clear();
}

namespace {

// a file of an OutputSet, for the writers' f.get() calls
struct OutputHandle {
  std::FILE* f;
  std::FILE* get() const { return f; }
};

std::string stem_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const auto dot = path.find_last_of('.');
  return (dot != std::string::npos && (slash == std::string::npos || dot > slash)) ? path.substr(0, dot) : path;
}

int status_code(std::uint8_t s) { return (s & kContact) ? ((s & kStick) ? 2 : 3) : 1; }
}  // namespace

std::string vtu_companion(const std::string& vtu_path) { return stem_of(vtu_path) + "_contact.vtu"; }

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ea, eb;
  const auto ca = std::filesystem::weakly_canonical(a, ea), cb = std::filesystem::weakly_canonical(b, eb);
  return (ea || eb) ? a == b : ca == cb;
}

void check_writable(const std::string& path) {
  const OutputTarget t = output_target(path);
  if (!t.refused.empty()) throw std::invalid_argument("output file '" + path + "' " + t.refused);
  if (t.special) {  // written in place: it must be writable (opening a FIFO here would block)
    if (::access(path.c_str(), W_OK) != 0) throw std::invalid_argument("cannot write output file '" + path + "'");
    return;
  }
  // a temporary next to it, as the writer will make
  std::string tmp;
  const int fd = make_temporary(path, tmp);
  if (fd < 0) throw std::invalid_argument("cannot write output file '" + path + "'");
  ::close(fd);
  ::unlink(tmp.c_str());
}

void write_text(OutputSet& out, const std::string& path, const std::string& contents) {
  std::FILE* f = out.create(path);
  std::fwrite(contents.data(), 1, contents.size(), f);
}

void write_file_atomic(const std::string& path, const std::string& contents) {
  OutputSet out;
  write_text(out, path, contents);
  out.publish();
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

Json& Json::num(const std::string& k, double v) {
  items_.push_back({k, json_number(v)});
  return *this;
}
Json& Json::integer(const std::string& k, long long v) {
  items_.push_back({k, std::to_string(v)});
  return *this;
}
Json& Json::boolean(const std::string& k, bool v) {
  items_.push_back({k, v ? "true" : "false"});
  return *this;
}
Json& Json::str(const std::string& k, const std::string& v) {
  std::string e = "\"";
  for (char c : v) {
    if (c == '"' || c == '\\') e += '\\';
    e += c;
  }
  items_.push_back({k, e + "\""});
  return *this;
}
Json& Json::null(const std::string& k) {
  items_.push_back({k, "null"});
  return *this;
}
Json& Json::array(const std::string& k, const std::vector<double>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + json_number(v[i]);
  items_.push_back({k, s + "]"});
  return *this;
}
Json& Json::raw(const std::string& k, const std::string& json) {
  items_.push_back({k, json});
  return *this;
}
std::string Json::render() const {
  std::string s = "{";
  for (size_t i = 0; i < items_.size(); ++i) s += (i ? ", " : "") + ("\"" + items_[i].first + "\": ") + items_[i].second;
  return s + "}";
}

void write_contact_csv(OutputSet& out, const std::string& path, const Problem& P, const ContactFields& c) {
  OutputHandle f{out.create(path)};
  const index p = P.contact_nodes();
  const GridDims& g = P.grid;
  std::fprintf(f.get(), "ix,iy,x,y,ux,uy,uz,lambda,phi,gap,contact,stick\n");
  for (index i = 0; i < p; ++i) {
    const index ix = 1 + i % g.ex, iy = i / g.ex;
    const std::uint8_t s = (*c.status)[i];
    std::fprintf(f.get(), "%lld,%lld,%.10g,%.10g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%d,%d\n", (long long)ix,
                 (long long)iy, g.x0 + ix * g.hx(), g.y0 + iy * g.hy(), (*c.u)[i], (*c.u)[p + i], (*c.u)[2 * p + i],
                 (*c.lambda)[i], (*c.phi)[i], (*c.gap)[i], (s & kContact) ? 1 : 0, (s & kStick) ? 1 : 0);
  }
}

namespace {
void vtu_header(std::FILE* f, index points, index cells) {
  std::fprintf(f,
               "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
               "byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"%lld\" "
               "NumberOfCells=\"%lld\">\n",
               (long long)points, (long long)cells);
}
void vtu_cells(std::FILE* f, const std::vector<index>& conn, int per_cell, int vtk_type) {
  const index cells = index(conn.size()) / per_cell;
  std::fprintf(f, "<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
  for (index i = 0; i < index(conn.size()); ++i) std::fprintf(f, "%lld%c", (long long)conn[i], (i + 1) % per_cell ? ' ' : '\n');
  std::fprintf(f, "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
  for (index c = 0; c < cells; ++c) std::fprintf(f, "%lld\n", (long long)(per_cell * (c + 1)));
  std::fprintf(f, "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
  for (index c = 0; c < cells; ++c) std::fprintf(f, "%d\n", vtk_type);
  std::fprintf(f, "</DataArray>\n</Cells>\n");
}
}  // namespace

std::string write_vtu(OutputSet& out, const std::string& path, const Problem& P, const std::vector<real>& u_full,
                      const ContactFields& c) {
  const GridDims& g = P.grid;
  const index N = g.nodes(), p = P.contact_nodes(), M = g.nx() * g.ny();
  // per grid node: contact node id or -1
  std::vector<index> cid(M, -1);
  for (index i = 0; i < p; ++i) cid[P.contact_grid_node(i)] = i;
  {
    OutputHandle f{out.create(path)};
    vtu_header(f.get(), N, g.ex * g.ey * g.ez);
    std::fprintf(f.get(), "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for (index iz = 0; iz < g.nz(); ++iz)
      for (index iy = 0; iy < g.ny(); ++iy)
        for (index ix = 0; ix < g.nx(); ++ix)
          std::fprintf(f.get(), "%.9g %.9g %.9g\n", g.x0 + ix * g.hx(), g.y0 + iy * g.hy(), g.z0 + iz * g.hz());
    std::fprintf(f.get(), "</DataArray>\n</Points>\n");
    std::vector<index> conn;
    conn.reserve(size_t(8 * g.ex * g.ey * g.ez));
    const int order[8] = {0, 1, 3, 2, 4, 5, 7, 6};  // VTK_HEXAHEDRON node order
    for (index ez = 0; ez < g.ez; ++ez)
      for (index ey = 0; ey < g.ey; ++ey)
        for (index ex = 0; ex < g.ex; ++ex)
          for (int k : order) conn.push_back(g.node(ex + (k & 1), ey + ((k >> 1) & 1), ez + ((k >> 2) & 1)));
    vtu_cells(f.get(), conn, 8, 12);
    std::fprintf(f.get(), "<PointData Vectors=\"displacement\">\n");
    std::fprintf(f.get(), "<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for (index n = 0; n < N; ++n) std::fprintf(f.get(), "%.12g %.12g %.12g\n", u_full[n], u_full[N + n], u_full[2 * N + n]);
    std::fprintf(f.get(), "</DataArray>\n<DataArray type=\"Float64\" Name=\"contact_force\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for (index n = 0; n < N; ++n) {
      const index i = n < M ? cid[n] : -1;
      if (i < 0)
        std::fprintf(f.get(), "0 0 0\n");
      else
        std::fprintf(f.get(), "%.12g %.12g %.12g\n", (*c.r)[i], (*c.r)[p + i], (*c.lambda)[i]);
    }
    std::fprintf(f.get(), "</DataArray>\n<DataArray type=\"UInt8\" Name=\"contact_status\" format=\"ascii\">\n");
    for (index n = 0; n < N; ++n) {
      const index i = n < M ? cid[n] : -1;
      std::fprintf(f.get(), "%d\n", i < 0 ? 0 : status_code((*c.status)[i]));
    }
    std::fprintf(f.get(), "</DataArray>\n</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
  }
  // contact face: the bottom plane as quads, its own point numbering
  const std::string cpath = vtu_companion(path);
  OutputHandle f{out.create(cpath)};
  vtu_header(f.get(), M, g.ex * g.ey);
  std::fprintf(f.get(), "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
  for (index n = 0; n < M; ++n) std::fprintf(f.get(), "%.9g %.9g %.9g\n", g.x0 + (n % g.nx()) * g.hx(), g.y0 + (n / g.nx()) * g.hy(), g.z0);
  std::fprintf(f.get(), "</DataArray>\n</Points>\n");
  std::vector<index> conn;
  for (index ey = 0; ey < g.ey; ++ey)
    for (index ex = 0; ex < g.ex; ++ex)
      for (index k : {index(0), index(1), g.nx() + 1, g.nx()}) conn.push_back(ex + g.nx() * ey + k);
  vtu_cells(f.get(), conn, 4, 9);
  std::fprintf(f.get(), "<PointData Vectors=\"displacement\">\n<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n");
  for (index n = 0; n < M; ++n) std::fprintf(f.get(), "%.12g %.12g %.12g\n", u_full[n], u_full[N + n], u_full[2 * N + n]);
  std::fprintf(f.get(), "</DataArray>\n<DataArray type=\"Float64\" Name=\"lambda\" format=\"ascii\">\n");
  for (index n = 0; n < M; ++n) std::fprintf(f.get(), "%.12g\n", cid[n] < 0 ? 0.0 : (*c.lambda)[cid[n]]);
  std::fprintf(f.get(), "</DataArray>\n<DataArray type=\"UInt8\" Name=\"contact_status\" format=\"ascii\">\n");
  for (index n = 0; n < M; ++n) std::fprintf(f.get(), "%d\n", cid[n] < 0 ? 0 : status_code((*c.status)[cid[n]]));
  std::fprintf(f.get(), "</DataArray>\n</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
  return cpath;
}

}  // namespace tresca
