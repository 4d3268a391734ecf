// VTK XML output for ParaView: the body as an unstructured grid of
// hexahedra, the contact face as quads, and .pvd collections that play a
// sequence of them (the levels of --table, the iterates of a Newton solve).
//
// Binary (the default) is VTK's appended raw encoding compressed with LZMA
// (compressor="vtkLZMADataCompressor", header_type="UInt64"; ParaView reads
// it since 5.5): every array is a header [blocks, block size, size of a
// partial last block (0: full), compressed size of each block] followed by
// the blocks, each one .xz stream, compressed in parallel. Values are the
// solver's doubles exactly.
// ASCII writes the same arrays as text (12 significant digits).
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "core/io/output.hpp"
#include "core/parallel/slab.hpp"

namespace tresca {

enum class VtkFormat { binary, ascii };
// "binary" or "ascii"; throws std::invalid_argument naming `option` otherwise
VtkFormat parse_vtk_format(const std::string& s, const std::string& option);

// The body (the undeformed mesh) with point data displacement [m],
// contact_force [N] (friction x, y and normal lambda on contact nodes),
// contact_pressure [Pa] (lambda over the node's share of the face's area)
// and contact_status (0 not a contact node, 1 separated, 2 stick, 3 slip),
// and cell data stress [Pa] (Cauchy, at the cell's centre; xx yy zz xy yz
// xz) and von_mises [Pa]; the contact face (quads, with the same point data)
// goes to vtu_companion(path). Every file says so in an XML comment
// (docs/outputs.md). Returns the second file's path.
std::string write_vtu(OutputSet& out, const std::string& path, const Problem& P, const Field<real>& u_full,
                      const ContactFields& c, VtkFormat format = VtkFormat::binary);

// Several ranks (ParaView's parallel format): every rank writes its rows of
// the body (and the ghost row above, so the pieces share the rows between
// them) to "<stem>_p<rank>.vtu" from its slab vector u_local (slab.hpp, its
// ghost rows current); rank 0 also writes the index "<stem>.pvtu" and the
// contact face to vtu_companion(path) (from the contact vectors, which every
// rank holds whole). Returns the face file's path on rank 0, "" elsewhere.
std::string write_pvtu(OutputSet& out, const std::string& path, const Problem& P, const Slab& s,
                       const Field<real>& u_local, const ContactFields& c, VtkFormat format = VtkFormat::binary);
std::string pvtu_piece_name(const std::string& path, int rank);

// A ParaView collection: each (time, file) is one step; a step's files are
// its parts (here the body and its contact face). `files` are written
// relative to the .pvd's directory.
struct PvdStep {
  double time;
  std::vector<std::string> files;
};
void write_pvd(OutputSet& out, const std::string& path, const std::vector<PvdStep>& steps);

// "<stem><suffix>.vtu" for "<stem>.vtu": the name of one step of a sequence
std::string vtu_step_name(const std::string& vtu_path, const std::string& suffix);
// "<stem>.pvd" for "<stem>.vtu"
std::string pvd_name(const std::string& vtu_path);

}  // namespace tresca
