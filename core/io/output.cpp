#include "core/io/output.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
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
constexpr int kMaxLive = 4096;
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
    if (!f_) return;  // finished before
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

void OutputSet::finish() {
  for (auto& f : files_) f->finish();
}

void OutputSet::publish() {
  for (auto& f : files_) f->finish();  // every file complete on disk first
  for (auto& f : files_) f->publish();
  files_.clear();
}

std::string path_stem(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const auto dot = path.find_last_of('.');
  return (dot != std::string::npos && (slash == std::string::npos || dot > slash)) ? path.substr(0, dot) : path;
}

std::string xml_escaped(const std::string& s) {
  std::string e;
  for (char c : s) {
    switch (c) {
      case '&': e += "&amp;"; break;
      case '<': e += "&lt;"; break;
      case '>': e += "&gt;"; break;
      case '"': e += "&quot;"; break;
      case '\'': e += "&apos;"; break;
      default: e += c;
    }
  }
  return e;
}

std::string vtu_companion(const std::string& vtu_path) { return path_stem(vtu_path) + "_contact.vtu"; }

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

std::string read_text_file(const std::string& path, const std::string& what) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument("cannot read " + what + " '" + path + "'");
  std::ostringstream os;
  os << in.rdbuf();
  if (in.bad()) throw std::invalid_argument("cannot read " + what + " '" + path + "'");
  return os.str();
}

void write_file_atomic(const std::string& path, const std::string& contents) {
  OutputSet out;
  write_text(out, path, contents);
  out.publish();
}

std::string json_text(const Json& j) { return j.dump(1) + "\n"; }

void write_contact_csv(OutputSet& out, const std::string& path, const Problem& P, const ContactFields& c) {
  std::FILE* f = out.create(path);  // owned by the set
  const index p = P.contact_nodes();
  const GridDims& g = P.grid;
  std::fprintf(f, "ix,iy,x,y,ux,uy,uz,lambda,phi,gap,contact,stick\n");
  for (index i = 0; i < p; ++i) {
    const index ix = 1 + i % g.ex, iy = i / g.ex;
    const auto [x, y] = contact_position(g, i);
    const ContactState s = contact_state((*c.status)[i]);  // separation first, as every output
    std::fprintf(f, "%lld,%lld,%.10g,%.10g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%d,%d\n", (long long)ix,
                 (long long)iy, x, y, (*c.u)[i], (*c.u)[p + i], (*c.u)[2 * p + i],
                 (*c.lambda)[i], (*c.phi)[i], (*c.gap)[i], s != ContactState::separated ? 1 : 0,
                 s == ContactState::stick ? 1 : 0);
  }
}

}  // namespace tresca
