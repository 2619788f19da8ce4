// Reading and writing triangle surfaces.
//
// STL, OBJ, OFF and PLY are parsed by hand: the format libraries at hand (VTK's readers, CGAL's IO)
// either skip bad records silently or fail with a generic message (VTK 9.1's PLY reader even crashes
// on a truncated binary file), whereas a user who exported a broken file needs to be told the line
// or binary record that is wrong and what is wrong with it. VTP (XML with appended, possibly
// compressed data) is read with VTK, whose messages are captured and turned into InputError; its
// records are then validated here.
//
// All readers return the file's polygon soup as stored: no vertex is merged, no triangle is dropped, so
// that triangle i of the result is record i of the file (after fanning polygons) and the messages of
// check_surface() can point back into the file.
#include "mesher/surface_io.h"

#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkTriangleFilter.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iostream>
#include <sstream>
#include <string_view>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/number_parse.h"
#include "common/paths.h"
#include "mesher/units.h"
#include "mesher/vtk_messages.h"

namespace hexbite {

namespace {

namespace fs = std::filesystem;

const char* const kAcceptedExtensions = ".stl, .obj, .ply, .off, .vtp";

// ------------------------------------------------------------------------------------------------
// Small helpers shared by the readers.

void require_known_extension(const std::string& path, const std::string& ext, const char* verb) {
  if (ext == ".stl" || ext == ".obj" || ext == ".ply" || ext == ".off" || ext == ".vtp") return;
  const std::string shown = ext.empty() ? "no extension" : "unknown extension '" + ext + "'";
  throw InputError(std::string("cannot ") + verb + " surface " + quoted(path) + ": " + shown +
                   "; accepted surface formats are " + kAcceptedExtensions + " (any case)");
}

// Checks existence and size first so that these two common mistakes get their own messages.
void require_readable_nonempty(const std::string& path) {
  require_regular_file(path, "surface file");
  std::error_code ec;
  if (fs::file_size(path, ec) == 0)
    throw InputError("surface file " + quoted(path) +
                     " is empty (0 bytes): the export or download did not finish; export it again");
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open surface file " + quoted(path) + ": check its permissions");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Lengths in messages: enough digits to find the spot, not the full round-trip precision.
std::string num(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

// Every coordinate must be a finite number; `where` names the line, record or vertex.
void require_finite(const std::string& path, const std::string& where, const Vec3& p) {
  for (int k = 0; k < 3; ++k) {
    if (std::isfinite(p[k])) continue;
    const char* axis = k == 0 ? "x" : k == 1 ? "y" : "z";
    const std::string what = std::isnan(p[k]) ? "is NaN (not a number)" : "is infinite";
    throw InputError(quoted(path) + " " + where + ": the " + axis + " coordinate " + what +
                     "; every coordinate must be a finite number: repair the surface where it was made "
                     "and export it again");
  }
}

void scale_in_place(TriSurface& s, double scale) {
  for (Vec3& p : s.vertices)
    for (double& c : p) c *= scale;
}

void require_triangles(const std::string& path, const TriSurface& s) {
  if (s.triangles.empty())
    throw InputError("surface file " + quoted(path) +
                     " contains no triangles: it holds no faces (only points or lines?); export the surface "
                     "as a triangle mesh");
}

// For a header count beyond what a TriSurface indexes (int): "4000000000 vertices, more than ...".
std::string too_many(long long count, const std::string& what) {
  return std::to_string(count) + " " + what +
         ", more than hexbite reads (at most 2147483647 = 2^31 - 1): the " +
         "count is damaged, or the surface must be reduced first";
}

// Appends the polygon corners[0..n) fanned around its first corner: (0, i, i + 1).
void add_fanned(TriSurface& s, const std::vector<int>& corners) {
  for (std::size_t i = 1; i + 1 < corners.size(); ++i)
    s.triangles.push_back({corners[0], corners[i], corners[i + 1]});
}

// Splits text into numbered lines (1-based), dropping a trailing '\r' and, when asked, a '#' comment.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}

  // Next line split into whitespace-separated tokens; false at the end of the text. With `join_continued`
  // (OBJ), a line ending in a backslash continues on the next one.
  bool next(std::vector<std::string_view>& tokens, bool strip_comments, bool join_continued = false) {
    tokens.clear();
    if (pos_ >= text_.size()) return false;
    first_line_ = line_ + 1;
    bool continued = true;
    while (continued && pos_ < text_.size()) {
      std::size_t end = text_.find('\n', pos_);
      if (end == std::string_view::npos) end = text_.size();
      std::string_view line = text_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++line_;
      if (strip_comments) line = line.substr(0, line.find('#'));
      const std::size_t last = line.find_last_not_of(" \t\r\f\v");
      continued = join_continued && last != std::string_view::npos && line[last] == '\\';
      if (continued) line = line.substr(0, last);
      std::size_t i = 0;
      while (i < line.size()) {
        while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        std::size_t j = i;
        while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
        if (j > i) tokens.push_back(line.substr(i, j - i));
        i = j;
      }
    }
    return true;
  }

  std::size_t line() const { return line_; }     // the last line read
  std::size_t position() const { return pos_; }  // byte offset of the next line
  // "line 7", or "lines 7-8" for a line continued on the next.
  std::string where() const {
    return first_line_ == line_ ? "line " + std::to_string(line_)
                                : "lines " + std::to_string(first_line_) + "-" + std::to_string(line_);
  }

 private:
  std::string_view text_;
  std::size_t pos_ = 0, line_ = 0, first_line_ = 0;
};

std::string joined(const std::vector<std::string_view>& tokens) {
  std::string s;
  for (std::size_t i = 0; i < tokens.size(); ++i) {
    if (i) s += ' ';
    s += tokens[i];
  }
  return s.size() > 80 ? s.substr(0, 77) + "..." : s;
}

// Reads three coordinates from tokens[first..first+3).
bool parse_point(const std::vector<std::string_view>& tokens, std::size_t first, Vec3& p) {
  if (tokens.size() < first + 3) return false;
  for (int k = 0; k < 3; ++k)
    if (!parse_double(tokens[first + k], p[k])) return false;
  return true;
}

// ------------------------------------------------------------------------------------------------
// STL

std::uint32_t get_u32(const std::string& bytes, std::size_t at) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + at);
  return std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 | std::uint32_t(b[2]) << 16 |
         std::uint32_t(b[3]) << 24;
}

float get_f32(const std::string& bytes, std::size_t at) {
  const std::uint32_t u = get_u32(bytes, at);
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

// A text STL contains no control characters but white space; any other one (a binary record's zero
// attribute bytes, for one) means binary, whatever the first 80 bytes say (many binary exporters start
// their header with "solid"). Bytes from 128 up are text: a solid named in UTF-8 ("solid Unterkiefer_ä").
bool is_text(const std::string& bytes) {
  return std::all_of(bytes.begin(), bytes.end(), [](char ch) {
    const auto c = static_cast<unsigned char>(ch);
    return (c >= 32 && c != 127) || c == '\n' || c == '\r' || c == '\t' || c == '\f' || c == '\v';
  });
}

// The first word of a text file, after white space.
std::string first_word(const std::string& bytes) {
  std::size_t i = 0;
  while (i < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[i]))) ++i;
  std::size_t end = i;
  while (end < bytes.size() && !std::isspace(static_cast<unsigned char>(bytes[end]))) ++end;
  return bytes.substr(i, end - i);
}

// Keywords of text formats are compared in lower case: exporters write "SOLID", "Facet", "VERTEX" too.
std::string lower_case(std::string_view word) {
  std::string s(word);
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

bool looks_like_ascii_stl(const std::string& bytes) {
  return lower_case(first_word(bytes)).rfind("solid", 0) == 0 && is_text(bytes);
}

TriSurface read_binary_stl(const std::string& path, const std::string& bytes) {
  const std::uint32_t n = get_u32(bytes, 80);
  TriSurface s;
  s.vertices.reserve(3 * std::size_t(n));
  s.triangles.reserve(n);
  for (std::uint32_t t = 0; t < n; ++t) {
    // Record layout: normal (3 floats, ignored: recomputed from the corners), 3 corners, attribute.
    const std::size_t record = 84 + 50 * std::size_t(t);
    for (int c = 0; c < 3; ++c) {
      const std::size_t at = record + 12 + 12 * std::size_t(c);
      const Vec3 p{get_f32(bytes, at), get_f32(bytes, at + 4), get_f32(bytes, at + 8)};
      require_finite(path, "triangle record " + std::to_string(t) + " (0-based), corner " + std::to_string(c),
                     p);
      s.vertices.push_back(p);
    }
    const int v = static_cast<int>(3 * t);
    s.triangles.push_back({v, v + 1, v + 2});
  }
  return s;
}

// Read by statements rather than by lines: a line may hold several of them (some exporters write the whole
// file on one line), and each statement's words are on the line of its keyword.
TriSurface read_ascii_stl(const std::string& path, const std::string& bytes) {
  TriSurface s;
  LineReader lines(bytes);
  std::vector<std::string_view> tok;
  std::vector<int> loop;  // corners of the current facet
  bool in_facet = false, in_loop = false;
  std::size_t facet_line = 0;
  auto malformed = [&](const std::string& expected) {
    return InputError(quoted(path) + " " + lines.where() + ": malformed ASCII STL line '" + joined(tok) +
                      "': expected " + expected + "; fix the line or export the surface again");
  };
  while (lines.next(tok, false)) {
    std::size_t i = 0;  // the next word of the line
    // Skips the words up to the next one of `stops` on this line: a solid's name, a facet's normal.
    auto skip_to = [&](std::initializer_list<const char*> stops) {
      while (i < tok.size() &&
             std::none_of(stops.begin(), stops.end(), [&](const char* k) { return lower_case(tok[i]) == k; }))
        ++i;
    };
    while (i < tok.size()) {
      const std::string key = lower_case(tok[i++]);
      if (key == "solid" || key == "endsolid") {
        if (in_facet) throw malformed("'endfacet' before '" + std::string(tok[i - 1]) + "'");
        if (key == "solid")
          skip_to({"facet", "endsolid"});
        else
          skip_to({"solid"});
      } else if (key == "facet") {
        if (in_facet) throw malformed("'endfacet' before the next facet");
        in_facet = true;
        facet_line = lines.line();
        skip_to({"outer"});  // the normal is recomputed from the corners
      } else if (key == "outer") {
        if (!in_facet || in_loop || i == tok.size() || lower_case(tok[i]) != "loop")
          throw malformed("'outer loop' directly after 'facet normal nx ny nz'");
        ++i;
        in_loop = true;
        loop.clear();
      } else if (key == "vertex") {
        if (!in_loop) throw malformed("'vertex' only between 'outer loop' and 'endloop'");
        Vec3 p;
        double extra = 0.0;
        if (!parse_point(tok, i, p) || (i + 3 < tok.size() && parse_double(tok[i + 3], extra)))
          throw malformed("'vertex x y z' with three numbers");
        i += 3;
        require_finite(path, lines.where(), p);
        loop.push_back(static_cast<int>(s.vertices.size()));
        s.vertices.push_back(p);
      } else if (key == "endloop") {
        if (!in_loop) throw malformed("'endloop' only after 'outer loop'");
        if (loop.size() < 3)
          throw malformed("at least three 'vertex' lines in the facet starting at line " +
                          std::to_string(facet_line));
        add_fanned(s, loop);
        in_loop = false;
      } else if (key == "endfacet") {
        if (!in_facet || in_loop) throw malformed("'endloop' before 'endfacet'");
        in_facet = false;
      } else {
        throw malformed("an STL keyword (solid, facet, outer loop, vertex, endloop, endfacet, endsolid)");
      }
    }
  }
  if (in_facet)
    throw InputError(quoted(path) + ": the file ends inside the facet that starts at line " +
                     std::to_string(facet_line) + ": it was cut off; export it again");
  return s;
}

TriSurface read_stl(const std::string& path) {
  const std::string bytes = read_bytes(path);
  // A binary STL is exactly 84 + 50 n bytes, n being the count stored at byte 80. This rule, not the
  // word "solid" at the start, decides: binary exporters often begin their header with "solid" too.
  if (bytes.size() >= 84 && bytes.size() == 84 + 50 * std::uint64_t(get_u32(bytes, 80)))
    return read_binary_stl(path, bytes);
  const std::string text(without_utf8_bom(bytes));
  if (looks_like_ascii_stl(text)) return read_ascii_stl(path, text);
  // Text that is no ASCII STL was called a corrupt binary STL announcing some billion triangles.
  if (is_text(text)) {
    const std::string word = first_word(text);
    const std::string kind = word == "v" || word == "vn" || word == "f" || word == "o" || word == "g" ||
                                     word == "mtllib" || word[0] == '#'
                                 ? "an OBJ file"
                             : word == "ply"                         ? "a PLY file"
                             : word.find("OFF") != std::string::npos ? "an OFF file"
                                                                     : "";
    throw InputError(
        "surface file " + quoted(path) + " is not an STL: it is text that does not begin with " +
        "'solid', as an ASCII STL does" +
        (kind.empty() ? std::string() : "; it looks like " + kind + ": give it the extension of its format") +
        (kind.empty() ? "; export it as STL again" : ""));
  }
  if (bytes.size() < 84)
    throw InputError("surface file " + quoted(path) +
                     " is a truncated binary STL: the header alone needs 84 bytes but the file has " +
                     std::to_string(bytes.size()) + " bytes; export it again");
  const std::uint64_t n = get_u32(bytes, 80), expected = 84 + 50 * n;
  const std::string announced = "its header announces " + std::to_string(n) +
                                " triangles, which take 84 + 50 x " + std::to_string(n) + " = " +
                                std::to_string(expected) + " bytes, but the file has " +
                                std::to_string(bytes.size()) + " bytes";
  if (bytes.size() < expected)
    throw InputError("surface file " + quoted(path) + " is a truncated or corrupt binary STL: " + announced +
                     " (missing " + std::to_string(expected - bytes.size()) +
                     "); export or download it again");
  // Fewer bytes than a record after the announced ones: a line end or padding some tools append, not data.
  const std::uint64_t extra = bytes.size() - expected;
  if (extra < 50) {
    std::cerr << "hexbite: warning: " << quoted(path) << ": " << announced << " (" << extra
              << " more, less than a triangle record); the " << n
              << " triangles are read and the extra bytes ignored\n";
    return read_binary_stl(path, bytes);
  }
  throw InputError("surface file " + quoted(path) + " is a corrupt binary STL: " + announced + ", " +
                   std::to_string(extra) +
                   " more: the count is wrong or other data was appended; export or " + "download it again");
}

// ------------------------------------------------------------------------------------------------
// OBJ: "v x y z [w | r g b]" and "f a b c ..." with a, a/t, a//n or a/t/n; 1-based indices, negative
// ones count back from the last vertex defined so far. Other statements carry no surface geometry.

bool is_other_obj_statement(std::string_view key) {
  static const char* const known[] = {
      "vt",     "vn",         "vp",        "l",      "p",     "g",    "o",    "s",     "mg",       "usemtl",
      "mtllib", "usemap",     "maplib",    "cstype", "deg",   "bmat", "step", "curv",  "curv2",    "surf",
      "parm",   "trim",       "hole",      "scrv",   "sp",    "end",  "con",  "bevel", "c_interp", "d_interp",
      "lod",    "shadow_obj", "trace_obj", "ctech",  "stech", "call", "csh"};
  return std::any_of(std::begin(known), std::end(known), [&](const char* k) { return key == k; });
}

TriSurface read_obj(const std::string& path) {
  const std::string bytes = read_bytes(path);
  TriSurface s;
  LineReader lines(without_utf8_bom(bytes));
  std::vector<std::string_view> tok;
  std::vector<int> corners;
  // Positive indices may (in lenient exporters) refer to vertices defined further down: they are
  // checked against the final count, remembering the line of each face for the message.
  long long max_positive = 0;
  std::string max_where;
  while (lines.next(tok, true, true)) {
    if (tok.empty()) continue;
    const std::string_view key = tok[0];
    if (key == "v") {
      Vec3 p;
      if (tok.size() < 4 || tok.size() > 7 || !parse_point(tok, 1, p))
        throw InputError(
            quoted(path) + " " + lines.where() + ": malformed OBJ vertex line '" + joined(tok) +
            "': expected 'v x y z' with three numbers; fix the line or export the surface again");
      require_finite(path, lines.where() + " (vertex " + std::to_string(s.vertices.size() + 1) + ")", p);
      s.vertices.push_back(p);
    } else if (key == "f") {
      corners.clear();
      for (std::size_t i = 1; i < tok.size(); ++i) {
        const std::string_view ref = tok[i].substr(0, tok[i].find('/'));
        long long index = 0;
        if (!parse_integer(ref, index))
          throw InputError(quoted(path) + " " + lines.where() + ": malformed OBJ face line '" + joined(tok) +
                           "': corner '" + std::string(tok[i]) +
                           "' is not v, v/t, v//n or v/t/n with integer indices");
        const long long count = static_cast<long long>(s.vertices.size());
        long long zero_based = index > 0 ? index - 1 : count + index;
        if (index == 0 || zero_based < 0)
          throw InputError(quoted(path) + " " + lines.where() + ": face index " + std::to_string(index) +
                           " is out of range: OBJ indices start at 1 (negative ones count back from the last "
                           "vertex), and " +
                           std::to_string(count) +
                           " vertices are defined above this line; fix the face or export again");
        if (index > 0 && index > max_positive) {
          max_positive = index;
          max_where = lines.where();
        }
        if (zero_based > INT32_MAX)
          throw InputError(quoted(path) + " " + lines.where() + ": face index " + std::to_string(index) +
                           " is beyond the supported 2^31 vertices");
        corners.push_back(static_cast<int>(zero_based));
      }
      if (corners.size() < 3)
        throw InputError(quoted(path) + " " + lines.where() + ": malformed OBJ face line '" + joined(tok) +
                         "': a face needs at least three corners");
      add_fanned(s, corners);
    } else if (!is_other_obj_statement(key)) {
      throw InputError(quoted(path) + " " + lines.where() + ": malformed OBJ line '" + joined(tok) + "': '" +
                       std::string(key) +
                       "' is not an OBJ statement (expected v, f, vt, vn, g, o, s, usemtl, ...)");
    }
  }
  if (max_positive > static_cast<long long>(s.vertices.size()))
    throw InputError(quoted(path) + " " + max_where + ": face index " + std::to_string(max_positive) +
                     " is out of range: the file defines only " + std::to_string(s.vertices.size()) +
                     " vertices (OBJ indices start at 1); fix the face");
  return s;
}

// ------------------------------------------------------------------------------------------------
// OFF: header keyword (OFF, COFF, NOFF, CNOFF, STOFF, ...), counts "nv nf ne", nv vertices
// "x y z [nx ny nz] [r g b [a]] [s t]" (the header's N, C and ST say which follow the coordinates), nf face
// lines "k i_1 .. i_k [colour]" with 0-based indices; '#' starts a comment. OFF is whitespace-delimited, so
// without colours (whose count varies) a line may hold several vertices; each lies on one line.

TriSurface read_off(const std::string& path) {
  const std::string bytes = read_bytes(path);
  LineReader lines(without_utf8_bom(bytes));
  std::vector<std::string_view> tok;
  auto next_nonblank = [&](const std::string& expecting) {
    while (lines.next(tok, true))
      if (!tok.empty()) return;
    throw InputError(quoted(path) + ": the file ends at line " + std::to_string(lines.line()) + " where " +
                     expecting + " was expected: it was cut off; export it again");
  };
  auto malformed = [&](const std::string& expected) {
    return InputError(quoted(path) + " " + lines.where() + ": malformed OFF line '" + joined(tok) +
                      "': expected " + expected + "; fix the line or export the surface again");
  };

  next_nonblank("the OFF header");
  const std::string_view keyword = tok[0];
  const bool keyword_ok = keyword.size() >= 3 && keyword.substr(keyword.size() - 3) == "OFF" &&
                          keyword.find_first_not_of("STCN") == keyword.size() - 3;
  if (!keyword_ok) throw malformed("the keyword OFF (or COFF, NOFF, CNOFF, STOFF) on the first line");
  const std::string_view prefix = keyword.substr(0, keyword.size() - 3);
  const bool normals = prefix.find('N') != std::string_view::npos,
             colours = prefix.find('C') != std::string_view::npos,
             texture = prefix.find("ST") != std::string_view::npos;
  const std::size_t per_vertex = 3 + (normals ? 3 : 0) + (texture ? 2 : 0);
  const std::string vertex_form = std::string("'x y z") + (normals ? " nx ny nz" : "") +
                                  (colours ? " r g b [a]" : "") + (texture ? " s t" : "") + "'";
  std::size_t first_count = 1;
  if (tok.size() == 1) {
    next_nonblank("the counts 'vertices faces edges'");
    first_count = 0;
  }
  long long nv = 0, nf = 0;
  if (tok.size() < first_count + 2 || !parse_integer(tok[first_count], nv) ||
      !parse_integer(tok[first_count + 1], nf) || nv < 0 || nf < 0)
    throw malformed("the counts 'vertices faces edges' as non-negative integers");
  if (nv > INT32_MAX || nf > INT32_MAX)
    throw InputError(quoted(path) + " " + lines.where() + ": the header announces " +
                     too_many(nv > INT32_MAX ? nv : nf, nv > INT32_MAX ? "vertices" : "faces") +
                     "; fix the counts or export the surface again");

  TriSurface s;
  // The count is the file's word: a damaged header ("2000000000 1 0") must not reserve more than the file
  // can hold (a vertex line takes at least 6 bytes), or it ends in std::bad_alloc instead of "cut off".
  s.vertices.reserve(std::min(static_cast<std::size_t>(nv), bytes.size() / 6));
  std::size_t next = tok.size();  // the next value of the current line
  for (long long i = 0; i < nv; ++i) {
    if (next == tok.size()) {
      next_nonblank("vertex " + std::to_string(i) + " of " + std::to_string(nv));
      next = 0;
    }
    auto vertex = [&] { return "vertex " + std::to_string(i) + " as " + vertex_form; };
    if (colours && (tok.size() < per_vertex || tok.size() > per_vertex + 4))
      throw malformed(vertex() + ", one vertex per line (the line has " + std::to_string(tok.size()) +
                      " values)");
    if (!colours && tok.size() - next < per_vertex)
      throw malformed(vertex() + ": the line's " + std::to_string(tok.size()) +
                      " values are not whole vertices of " + std::to_string(per_vertex) +
                      " values each (vertex colours need a COFF header)");
    Vec3 p;
    if (!parse_point(tok, next, p)) throw malformed(vertex());
    require_finite(path, lines.where() + " (vertex " + std::to_string(i) + ", 0-based)", p);
    s.vertices.push_back(p);
    next = colours ? tok.size() : next + per_vertex;
  }
  if (next < tok.size())
    throw malformed("no more values after vertex " + std::to_string(nv - 1) + ", the last of the " +
                    std::to_string(nv) + " the header announces (the faces follow, one per line)");
  std::vector<int> corners;
  for (long long f = 0; f < nf; ++f) {
    next_nonblank("face " + std::to_string(f) + " of " + std::to_string(nf));
    long long k = 0;
    if (!parse_integer(tok[0], k) || k < 3 || tok.size() < std::size_t(k) + 1)
      throw malformed("face " + std::to_string(f) + " as 'k i_1 ... i_k' with k >= 3 vertex indices");
    // A colour is at most 4 values; more is a second face on the line, or a wrong k.
    if (tok.size() > std::size_t(k) + 5)
      throw malformed("face " + std::to_string(f) +
                      " as 'k i_1 ... i_k [colour]' on a line of its own: after its " + std::to_string(k) +
                      " indices come " + std::to_string(tok.size() - std::size_t(k) - 1) +
                      " values, more than a colour's 4");
    corners.clear();
    for (long long i = 1; i <= k; ++i) {
      long long index = 0;
      if (!parse_integer(tok[i], index))
        throw malformed("integer vertex indices in face " + std::to_string(f));
      if (index < 0 || index >= nv)
        throw InputError(quoted(path) + " " + lines.where() + ": face " + std::to_string(f) +
                         " refers to vertex " + std::to_string(index) +
                         ", which is out of range: OFF indices start at 0 and the file has " +
                         std::to_string(nv) + " vertices; fix the face");
      corners.push_back(static_cast<int>(index));
    }
    add_fanned(s, corners);
  }
  // Data after the faces the header announces (a count too small, two files joined) was dropped silently.
  while (lines.next(tok, true))
    if (!tok.empty())
      throw InputError(quoted(path) + " " + lines.where() + ": '" + joined(tok) + "' after the " +
                       std::to_string(nf) +
                       " faces the header announces: its counts are wrong or two files were joined; fix the "
                       "counts or export the surface again");
  return s;
}

// ------------------------------------------------------------------------------------------------
// PLY (ASCII, binary little- and big-endian). Parsed by hand as well: VTK 9.1's vtkPLYReader
// crashes (heap corruption) on a truncated binary file instead of reporting it. Any elements and
// properties are accepted; "vertex" must have x, y, z and "face" a list "vertex_indices" (or
// "vertex_index"); other elements and properties are read past.

enum class PlyFormat { kAscii, kLittle, kBig };

struct PlyProperty {
  std::string name;
  std::string type;        // scalar type, or the item type of a list
  std::string count_type;  // non-empty for a list
};

struct PlyElement {
  std::string name;
  long long count = 0;
  std::vector<PlyProperty> properties;
};

int ply_type_size(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" ||
      type == "float32")
    return 4;
  if (type == "double" || type == "float64") return 8;
  return 0;
}

// Reads one binary value of `type` at `at` (bounds already checked) as a double.
double ply_binary_value(const std::string& bytes, std::size_t at, const std::string& type, bool big_endian) {
  const int size = ply_type_size(type);
  unsigned char b[8];
  for (int i = 0; i < size; ++i)
    b[i] = static_cast<unsigned char>(bytes[at + (big_endian ? size - 1 - i : i)]);
  std::uint64_t u = 0;
  for (int i = size - 1; i >= 0; --i) u = u << 8 | b[i];
  if (type == "float" || type == "float32") {
    float f;
    const auto u32 = static_cast<std::uint32_t>(u);
    std::memcpy(&f, &u32, 4);
    return f;
  }
  if (type == "double" || type == "float64") {
    double d;
    std::memcpy(&d, &u, 8);
    return d;
  }
  const bool is_signed = type == "char" || type == "int8" || type == "short" || type == "int16" ||
                         type == "int" || type == "int32";
  if (is_signed && size < 8 && (u >> (8 * size - 1)) & 1)
    return static_cast<double>(u) - std::ldexp(1.0, 8 * size);
  return static_cast<double>(u);
}

TriSurface read_ply(const std::string& path) {
  const std::string bytes = read_bytes(path);
  // The header is read after a UTF-8 byte order mark; binary offsets stay those of the file.
  const std::size_t bom = bytes.size() - without_utf8_bom(bytes).size();
  LineReader lines(std::string_view(bytes).substr(bom));
  std::vector<std::string_view> tok;
  auto header_error = [&](const std::string& what) {
    return InputError(quoted(path) + " " + lines.where() + ": " + what +
                      "; fix the PLY header or export again");
  };
  if (!lines.next(tok, false) || tok.size() != 1 || tok[0] != "ply")
    throw InputError(quoted(path) +
                     " is not a valid PLY file: its first line must be 'ply'; export it again");
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  bool have_format = false, ended = false;
  while (!ended && lines.next(tok, false)) {
    if (tok.empty() || tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "format") {
      if (tok.size() != 3)
        throw header_error("expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
      if (tok[1] == "ascii")
        format = PlyFormat::kAscii;
      else if (tok[1] == "binary_little_endian")
        format = PlyFormat::kLittle;
      else if (tok[1] == "binary_big_endian")
        format = PlyFormat::kBig;
      else
        throw header_error("unknown format '" + std::string(tok[1]) + "'");
      have_format = true;
    } else if (tok[0] == "element") {
      PlyElement e;
      if (tok.size() != 3 || !parse_integer(tok[2], e.count) || e.count < 0)
        throw header_error("expected 'element NAME COUNT' with a non-negative integer COUNT");
      e.name = std::string(tok[1]);
      if (e.count > INT32_MAX)
        throw header_error("'element " + e.name + "' announces " + too_many(e.count, "records"));
      // A second vertex or face element (the first one empty, say) was read with the first one's property
      // places and crashed.
      if ((e.name == "vertex" || e.name == "face") &&
          std::any_of(elements.begin(), elements.end(),
                      [&](const PlyElement& x) { return x.name == e.name; }))
        throw header_error("a second 'element " + e.name +
                           "': a surface has one vertex and one face element");
      elements.push_back(e);
    } else if (tok[0] == "property") {
      if (elements.empty()) throw header_error("a property before any element");
      PlyProperty prop;
      if (tok.size() == 5 && tok[1] == "list") {
        prop = {std::string(tok[4]), std::string(tok[3]), std::string(tok[2])};
        if (!ply_type_size(prop.count_type) || !ply_type_size(prop.type) || prop.count_type == "float" ||
            prop.count_type == "double" || prop.count_type == "float32" || prop.count_type == "float64")
          throw header_error("unknown or non-integer list types in '" + joined(tok) + "'");
      } else if (tok.size() == 3) {
        prop = {std::string(tok[2]), std::string(tok[1]), ""};
        if (!ply_type_size(prop.type)) throw header_error("unknown property type '" + prop.type + "'");
      } else {
        throw header_error("expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'");
      }
      elements.back().properties.push_back(prop);
    } else if (tok[0] == "end_header") {
      ended = true;
    } else {
      throw header_error("unknown header line '" + joined(tok) + "'");
    }
  }
  if (!have_format || !ended)
    throw InputError(quoted(path) + ": the PLY header has no " +
                     (have_format ? "'end_header'" : "'format' line") + "; export it again");

  // Where x, y, z and the face list sit in their elements.
  TriSurface s;
  int coordinate[3] = {-1, -1, -1};
  int face_list = -1;
  for (const PlyElement& e : elements)
    for (std::size_t p = 0; p < e.properties.size(); ++p) {
      const PlyProperty& prop = e.properties[p];
      if (e.name == "vertex" && prop.count_type.empty() &&
          (prop.name == "x" || prop.name == "y" || prop.name == "z"))
        coordinate[prop.name[0] - 'x'] = static_cast<int>(p);
      if (e.name == "face" && !prop.count_type.empty() &&
          (prop.name == "vertex_indices" || prop.name == "vertex_index"))
        face_list = static_cast<int>(p);
    }
  const bool has_vertices = std::any_of(elements.begin(), elements.end(), [](const PlyElement& e) {
    return e.name == "vertex" && e.count > 0;
  });
  if (has_vertices && (coordinate[0] < 0 || coordinate[1] < 0 || coordinate[2] < 0))
    throw InputError(quoted(path) + ": the PLY element 'vertex' lacks one of the properties x, y, z");

  // The records follow the header line by line (ASCII) or byte by byte (binary). The faces' vertex lists are
  // checked after every element is read: the vertex element usually comes first, but the format allows
  // either order (a face element first was said to refer to vertices "out of range: the file has 0").
  std::size_t at = std::min(bom + lines.position(), bytes.size());
  const bool binary = format != PlyFormat::kAscii;
  const bool big = format == PlyFormat::kBig;
  LineReader body(std::string_view(bytes).substr(at));
  const std::size_t header_lines = lines.line();
  std::vector<double> scalars;
  std::vector<long long> list;
  std::vector<long long> face_indices;  // every face's list, one after another
  std::vector<std::size_t> face_ends;   // where each face's list ends in face_indices
  // ASCII records are read by values, as the header declares them: a line may hold several records (some
  // exporters write all vertices on one line), but a record does not continue on the next line.
  tok.clear();
  std::size_t next_token = 0;
  for (const PlyElement& e : elements) {
    const bool is_vertex = e.name == "vertex", is_face = e.name == "face";
    for (long long r = 0; r < e.count; ++r) {
      const std::string record = e.name + " " + std::to_string(r) + " (0-based)";
      auto cut_off = [&]() {
        return InputError(quoted(path) + ": the file ends in " + record + " of the " +
                          std::to_string(e.count) +
                          " announced by the header: it was cut off; export it again");
      };
      scalars.assign(e.properties.size(), 0.0);
      list.clear();
      if (!binary && next_token == tok.size()) {
        do {
          if (!body.next(tok, false)) throw cut_off();
        } while (tok.empty());
        next_token = 0;
      }
      const std::size_t record_start = next_token;
      auto ascii_value = [&](const std::string& type) {
        double v = 0.0;
        if (next_token >= tok.size())
          throw InputError(
              quoted(path) + " line " + std::to_string(header_lines + body.line()) + ": " + record +
              (record_start == 0 ? std::string(" has too few values")
                                 : " starts after value " + std::to_string(record_start) +
                                       " of the line and the line ends inside it: its " +
                                       std::to_string(tok.size()) + " values are not whole records") +
              "; fix the line or export again");
        const bool integer_type =
            type != "float" && type != "float32" && type != "double" && type != "float64";
        if (!parse_double(tok[next_token], v) || (integer_type && std::isfinite(v) && std::floor(v) != v))
          throw InputError(quoted(path) + " line " + std::to_string(header_lines + body.line()) +
                           ": malformed PLY value '" + std::string(tok[next_token]) + "' in " + record +
                           " (expected a " + type + "); fix the line or export again");
        ++next_token;
        return v;
      };
      auto binary_value = [&](const std::string& type) {
        const std::size_t size = static_cast<std::size_t>(ply_type_size(type));
        if (at + size > bytes.size()) throw cut_off();
        const double v = ply_binary_value(bytes, at, type, big);
        at += size;
        return v;
      };
      for (std::size_t p = 0; p < e.properties.size(); ++p) {
        const PlyProperty& prop = e.properties[p];
        auto value = [&](const std::string& type) { return binary ? binary_value(type) : ascii_value(type); };
        if (prop.count_type.empty()) {
          scalars[p] = value(prop.type);
          continue;
        }
        const double n = value(prop.count_type);
        if (n < 0) throw InputError(quoted(path) + ": " + record + " has a negative list length");
        for (long long k = 0; k < static_cast<long long>(n); ++k) {
          const double item = value(prop.type);
          if (is_face && static_cast<int>(p) == face_list) list.push_back(static_cast<long long>(item));
        }
      }
      if (is_vertex) {
        const Vec3 point{scalars[coordinate[0]], scalars[coordinate[1]], scalars[coordinate[2]]};
        require_finite(path, record, point);
        s.vertices.push_back(point);
      } else if (is_face && face_list >= 0) {
        if (list.size() < 3)
          throw InputError(quoted(path) + ": " + record + " has " + std::to_string(list.size()) +
                           " vertices; a face needs at least three");
        face_indices.insert(face_indices.end(), list.begin(), list.end());
        face_ends.push_back(face_indices.size());
      }
    }
  }
  // Data after the elements the header announces (a count too small, two files joined) was dropped
  // silently. Trailing line ends and blanks, which some exporters add after binary data, are fine.
  if (binary && bytes.find_first_not_of(" \t\r\n", at) != std::string::npos)
    throw InputError(quoted(path) + ": " + std::to_string(bytes.size() - at) + " bytes follow the " +
                     "elements the header announces (from byte " + std::to_string(at) + " of " +
                     std::to_string(bytes.size()) + "): its counts are wrong or two files were joined; " +
                     "fix the counts or export the surface again");
  if (!binary) {
    std::vector<std::string_view> rest(tok.begin() + static_cast<std::ptrdiff_t>(next_token), tok.end());
    while (rest.empty() && body.next(rest, false)) continue;
    if (!rest.empty())
      throw InputError(quoted(path) + " line " + std::to_string(header_lines + body.line()) + ": '" +
                       joined(rest) +
                       "' after the elements the header announces: its counts are wrong or two files were "
                       "joined; fix the counts or export the surface again");
  }
  std::vector<int> corners;
  for (std::size_t f = 0, begin = 0; f < face_ends.size(); begin = face_ends[f++]) {
    corners.clear();
    for (std::size_t k = begin; k < face_ends[f]; ++k) {
      const long long index = face_indices[k];
      if (index < 0 || index >= static_cast<long long>(s.vertices.size()))
        throw InputError(quoted(path) + ": face " + std::to_string(f) + " (0-based) refers to vertex " +
                         std::to_string(index) + ", which is out of range: the file has " +
                         std::to_string(s.vertices.size()) + " vertices (0-based indices); fix the face");
      corners.push_back(static_cast<int>(index));
    }
    add_fanned(s, corners);
  }
  return s;
}

// ------------------------------------------------------------------------------------------------
// VTP through VTK.

// Copies VTK points into the soup, each checked to be finite.
void copy_points(const std::string& path, vtkPoints* points, TriSurface& s) {
  const vtkIdType n = points ? points->GetNumberOfPoints() : 0;
  s.vertices.resize(static_cast<std::size_t>(n));
  for (vtkIdType i = 0; i < n; ++i) {
    double p[3];
    points->GetPoint(i, p);
    s.vertices[std::size_t(i)] = {p[0], p[1], p[2]};
    require_finite(path, "vertex " + std::to_string(i) + " (0-based)", s.vertices[std::size_t(i)]);
  }
}

// VTK readers copy point ids without checking them; `kind` names the cells in messages.
void require_cells_in_range(const std::string& path, vtkCellArray* cells, vtkIdType num_points,
                            const std::string& kind) {
  if (!cells) return;
  vtkIdType npts = 0;
  const vtkIdType* ids = nullptr;
  vtkIdType c = 0;
  for (cells->InitTraversal(); cells->GetNextCell(npts, ids); ++c)
    for (vtkIdType i = 0; i < npts; ++i)
      if (ids[i] < 0 || ids[i] >= num_points)
        throw InputError(quoted(path) + " " + kind + " " + std::to_string(c) +
                         " (0-based) refers to vertex " + std::to_string(ids[i]) +
                         ", which is out of range: the file has " + std::to_string(num_points) +
                         " vertices (0-based indices); fix the " + kind);
}

TriSurface read_vtp(const std::string& path) {
  VtkMessageCapture capture;
  vtkNew<vtkXMLPolyDataReader> reader;
  if (!reader->CanReadFile(path.c_str()))
    throw InputError(
        quoted(path) +
        " is not a VTK XML PolyData file: it must be XML with <VTKFile type=\"PolyData\">; export "
        "it again");
  reader->SetFileName(path.c_str());
  update_xml_reader(reader, path);
  vtkPolyData* data = reader->GetOutput();
  // Warnings (for example about an unknown array type) do not make a file unreadable; errors do.
  if (!capture.errors().empty() || !data)
    throw InputError(quoted(path) + " could not be read as VTP: " +
                     (capture.errors().empty() ? std::string("no data") : capture.errors()) +
                     "; export it again");
  const vtkIdType n = data->GetNumberOfPoints();
  // Validate before triangulating: vtkTriangleFilter does not check point ids.
  require_cells_in_range(path, data->GetPolys(), n, "polygon");
  require_cells_in_range(path, data->GetStrips(), n, "triangle strip");
  TriSurface s;
  copy_points(path, data->GetPoints(), s);

  // Polygons and strips become triangles; vertices and lines are not part of a surface.
  vtkNew<vtkTriangleFilter> triangulate;
  triangulate->SetInputData(data);
  triangulate->PassVertsOff();
  triangulate->PassLinesOff();
  triangulate->Update();
  vtkPolyData* tri = triangulate->GetOutput();
  if (tri->GetNumberOfPoints() != n)
    throw InputError(quoted(path) + ": triangulating the polygons changed the number of points");
  vtkIdType npts = 0;
  const vtkIdType* ids = nullptr;
  vtkCellArray* polys = tri->GetPolys();
  for (polys->InitTraversal(); polys->GetNextCell(npts, ids);)
    if (npts == 3)
      s.triangles.push_back({static_cast<int>(ids[0]), static_cast<int>(ids[1]), static_cast<int>(ids[2])});
  return s;
}

// ------------------------------------------------------------------------------------------------
// Writers. Text numbers use std::to_chars (shortest text that reads back to the same double), binary
// numbers are written little-endian byte by byte: the bytes depend on the surface only.

void put_u32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

void put_f32(std::string& out, float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  put_u32(out, u);
}

void put_f64(std::string& out, double d) {
  std::uint64_t u;
  std::memcpy(&u, &d, sizeof u);
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((u >> (8 * i)) & 0xff));
}

void put_number(std::string& out, double v) {
  char buf[32];
  auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, ptr);
}

void put_point(std::string& out, const Vec3& p) {
  put_number(out, p[0]);
  out += ' ';
  put_number(out, p[1]);
  out += ' ';
  put_number(out, p[2]);
}

std::string stl_bytes(const TriSurface& s) {
  std::string out;
  out.reserve(84 + 50 * s.triangles.size());
  // The header must not start with "solid", which would suggest an ASCII file to other readers.
  std::string header = "hexbite binary STL, millimetres";
  header.resize(80, ' ');
  out += header;
  put_u32(out, static_cast<std::uint32_t>(s.triangles.size()));
  for (const auto& t : s.triangles) {
    const Vec3 &a = s.vertices[t[0]], &b = s.vertices[t[1]], &c = s.vertices[t[2]];
    const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    Vec3 n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (double& x : n) x = len > 0 ? x / len : 0.0;
    for (double x : n) put_f32(out, static_cast<float>(x));
    for (int k = 0; k < 3; ++k)
      for (double x : s.vertices[t[k]]) put_f32(out, static_cast<float>(x));
    out.push_back('\0');  // attribute byte count: 0
    out.push_back('\0');
  }
  return out;
}

std::string obj_bytes(const TriSurface& s) {
  std::string out = "# hexbite surface, millimetres: " + std::to_string(s.vertices.size()) + " vertices, " +
                    std::to_string(s.triangles.size()) + " triangles\n";
  for (const Vec3& p : s.vertices) {
    out += "v ";
    put_point(out, p);
    out += '\n';
  }
  for (const auto& t : s.triangles)
    out += "f " + std::to_string(t[0] + 1) + ' ' + std::to_string(t[1] + 1) + ' ' + std::to_string(t[2] + 1) +
           '\n';
  return out;
}

std::string off_bytes(const TriSurface& s) {
  std::string out = "OFF\n# hexbite surface, millimetres\n" + std::to_string(s.vertices.size()) + ' ' +
                    std::to_string(s.triangles.size()) + " 0\n";
  for (const Vec3& p : s.vertices) {
    put_point(out, p);
    out += '\n';
  }
  for (const auto& t : s.triangles)
    out += "3 " + std::to_string(t[0]) + ' ' + std::to_string(t[1]) + ' ' + std::to_string(t[2]) + '\n';
  return out;
}

std::string ply_bytes(const TriSurface& s) {
  std::string out =
      "ply\nformat binary_little_endian 1.0\ncomment hexbite surface, millimetres\nelement vertex " +
      std::to_string(s.vertices.size()) +
      "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
      std::to_string(s.triangles.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Vec3& p : s.vertices)
    for (double x : p) put_f64(out, x);
  for (const auto& t : s.triangles) {
    out.push_back(3);
    for (int v : t) put_u32(out, static_cast<std::uint32_t>(v));
  }
  return out;
}

// The bytes of `s` as a binary VTK XML PolyData file; `path` is named in the error. Made in memory and then
// written and checked like the other formats: VTK writing to the file itself did not notice a write that
// failed (a full disk, a file size limit) and left an empty file with exit 0.
std::string vtp_bytes(const std::string& path, const TriSurface& s) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(s.vertices.size()));
  for (std::size_t i = 0; i < s.vertices.size(); ++i)
    points->SetPoint(static_cast<vtkIdType>(i), s.vertices[i].data());
  vtkNew<vtkCellArray> polys;
  polys->AllocateExact(static_cast<vtkIdType>(s.triangles.size()),
                       3 * static_cast<vtkIdType>(s.triangles.size()));
  for (const auto& t : s.triangles) {
    const vtkIdType ids[3] = {t[0], t[1], t[2]};
    polys->InsertNextCell(3, ids);
  }
  vtkNew<vtkPolyData> data;
  data->SetPoints(points);
  data->SetPolys(polys);

  VtkMessageCapture capture;
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->WriteToOutputStringOn();
  writer->SetInputData(data);
  writer->SetDataModeToBinary();
  if (writer->Write() != 1 || !capture.errors().empty())
    throw RunError("cannot write " + quoted(path) + ": " +
                   (capture.errors().empty() ? std::string("VTK writer failed") : capture.errors()));
  return writer->GetOutputString();
}

}  // namespace

TriSurface read_surface(const std::string& path, double scale_to_mm) {
  const std::string ext = lower_extension(path);
  require_known_extension(path, ext, "read");
  require_readable_nonempty(path);
  TriSurface s;
  if (ext == ".stl")
    s = read_stl(path);
  else if (ext == ".obj")
    s = read_obj(path);
  else if (ext == ".off")
    s = read_off(path);
  else if (ext == ".ply")
    s = read_ply(path);
  else
    s = read_vtp(path);
  require_triangles(path, s);
  if (scale_to_mm != 1.0) {
    scale_in_place(s, scale_to_mm);
    // Scaling a huge finite value can overflow; name the vertex when it does.
    for (std::size_t i = 0; i < s.vertices.size(); ++i)
      require_finite(path,
                     "vertex " + std::to_string(i) + " (0-based) after scaling to mm by " + num(scale_to_mm),
                     s.vertices[i]);
  }
  // A coordinate of a kilometre and more is a damaged file or a wrong unit, never a bone: the geometry's
  // predicates lose their precision there (the mesher stopped on a CGAL assertion), and an STL written from
  // it held infinities (its coordinates are floats).
  for (std::size_t i = 0; i < s.vertices.size(); ++i)
    for (int a = 0; a < 3; ++a)
      if (std::abs(s.vertices[i][a]) > kMaxCoordinateMm)
        throw InputError("surface file " + quoted(path) + ": vertex " + std::to_string(i) +
                         " (0-based) has the " + "xyz"[a] + " coordinate " + num(s.vertices[i][a]) +
                         " mm, beyond " + num(kMaxCoordinateMm) +
                         " mm in size: the file is damaged or its unit is wrong (--units)");
  return s;
}

void write_surface(const std::string& path, const TriSurface& surface) {
  const std::string ext = lower_extension(path);
  require_known_extension(path, ext, "write");
  std::string bytes;
  if (ext == ".vtp")
    bytes = vtp_bytes(path, surface);
  else if (ext == ".stl")
    bytes = stl_bytes(surface);
  else if (ext == ".obj")
    bytes = obj_bytes(surface);
  else if (ext == ".off")
    bytes = off_bytes(surface);
  else
    bytes = ply_bytes(surface);
  write_file_atomically(path, bytes);
}

}  // namespace hexbite
