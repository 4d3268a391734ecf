// Output writers. Every regular file is written completely or not at all:
// data go to a fresh temporary next to it (mkstemp: exclusive, never a
// symlink), flushed to disk and renamed over <path>, which keeps its
// permissions; special files (FIFOs, /dev/null) are written in place;
// directories are refused (output.cpp: OutputFile). Failures throw
// std::runtime_error naming the path.
#pragma once
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/fem/problem.hpp"

namespace tresca {

// Throws if `path` cannot be created (checked before a long run starts).
void check_writable(const std::string& path);
// "dir/name" for "dir/name.ext" (the path itself without an extension)
std::string path_stem(const std::string& path);
// s with XML's five special characters as entities (for attribute values)
std::string xml_escaped(const std::string& s);
// the contact-face file written next to a body VTU: "<stem>_contact.vtu"
std::string vtu_companion(const std::string& vtu_path);
// whether two output paths name the same file (also through "..", "." or
// symlinked directories; neither needs to exist)
bool same_file(const std::string& a, const std::string& b);
// The files of one run, written all or none: each goes to its own temporary
// (OutputFile's rules above), and publish() renames them only after every
// one of them is complete on disk. Destroyed unpublished (a failed write, an
// exception), the set removes its temporaries; SIGINT, SIGTERM and SIGHUP
// remove them too. So after an interruption a user has either the run's
// complete new outputs or the old ones, never a mixture or debris.
class OutputFile;
class OutputSet {
 public:
  OutputSet();
  ~OutputSet();
  std::FILE* create(const std::string& path);  // stays owned by the set
  // the files created so far complete on disk and closed (no longer
  // writable), still unpublished: for sets of many files
  void finish();
  void publish();

 private:
  std::vector<std::unique_ptr<OutputFile>> files_;
};
void write_text(OutputSet& out, const std::string& path, const std::string& contents);
// one file on its own: write_text + publish
void write_file_atomic(const std::string& path, const std::string& contents);
// a whole file's contents; throws std::invalid_argument "cannot read
// <what> '<path>'" if it cannot be opened or read
std::string read_text_file(const std::string& path, const std::string& what);

// JSON documents (run summaries, perf records): nlohmann's, keys in
// insertion order; non-finite numbers are written as null. `json_text`
// renders one as a file's contents (indented, newline-terminated).
using Json = nlohmann::ordered_json;
std::string json_text(const Json& j);

struct ContactFields {
  const std::vector<real>* u;       // 3p
  const std::vector<real>* lambda;  // p
  const std::vector<real>* r;       // 3p contact forces (r_τ, r_z)
  const std::vector<std::uint8_t>* status;
  const std::vector<real>* phi;     // p: Tresca bound per node
  const std::vector<real>* gap;     // p: gap to the obstacle per node
};

void write_contact_csv(OutputSet& out, const std::string& path, const Problem& P, const ContactFields& c);

}  // namespace tresca
