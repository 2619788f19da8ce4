#include "mesher/quad_surface_io.h"

#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkXMLPolyDataReader.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/number_parse.h"
#include "common/paths.h"
#include "mesher/vtk_messages.h"

namespace hexbite {

namespace {

namespace fs = std::filesystem;

void require_readable_nonempty(const std::string& path) {
  require_regular_file(path, "quad surface file");
  std::error_code ec;
  if (fs::file_size(path, ec) == 0)
    throw InputError("quad surface file " + quoted(path) + " is empty (0 bytes): export it again");
}

void require_finite(const std::string& path, const std::string& where, const Vec3& p) {
  for (double c : p)
    if (!std::isfinite(c))
      throw InputError(quoted(path) + " " + where +
                       ": a coordinate is NaN or infinite; every coordinate must be a finite number");
}

void require_quads(const std::string& path, const QuadSurface& s) {
  if (s.quads.empty())
    throw InputError("quad surface file " + quoted(path) +
                     " contains no quads: export the surface as a quad mesh");
}

// An OBJ face corner is "v", "v/vt", "v//vn" or "v/vt/vn"; only the vertex index matters here.
bool parse_index(std::string_view token, long& value) {
  token = token.substr(0, token.find('/'));
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  auto [ptr, ec] = std::from_chars(token.data(), end, value);
  return ec == std::errc() && ptr == end && !token.empty();
}

QuadSurface read_obj(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot open quad surface file " + quoted(path) + ": check its permissions");
  QuadSurface s;
  // Face corners are checked against the vertex count at the end, because OBJ allows faces to refer to
  // vertices defined later; the line of each face is kept for that message.
  std::vector<int> face_line;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line_no == 1) line = std::string(without_utf8_bom(line));
    if (!line.empty() && line.back() == '\r') line.pop_back();
    line = line.substr(0, line.find('#'));  // a comment, also at the end of a line, as for triangle OBJ
    std::istringstream tokens(line);
    std::string key;
    if (!(tokens >> key)) continue;
    const std::string where = "line " + std::to_string(line_no);
    std::vector<std::string> rest;
    for (std::string t; tokens >> t;) rest.push_back(t);
    if (key == "v") {
      Vec3 p{};
      if (rest.size() < 3 || !parse_double(rest[0], p[0]) || !parse_double(rest[1], p[1]) ||
          !parse_double(rest[2], p[2]))
        throw InputError(quoted(path) + " " + where + ": malformed vertex line '" + line +
                         "': expected 'v x y z'");
      require_finite(path, where, p);
      s.vertices.push_back(p);
    } else if (key == "f") {
      if (rest.size() != 4)
        throw InputError(quoted(path) + " " + where + ": face with " + std::to_string(rest.size()) +
                         " corners ('" + line +
                         "'); a quad surface holds only quads (4 corners): remesh "
                         "the surface with quads or use the grid method for triangle surfaces");
      std::array<int, 4> q{};
      for (int k = 0; k < 4; ++k) {
        long index = 0;
        if (!parse_index(rest[k], index) || index == 0)
          throw InputError(quoted(path) + " " + where + ": malformed face line '" + line +
                           "': corners are 1-based vertex indices");
        // Negative indices count back from the last vertex read so far.
        const long resolved = index > 0 ? index - 1 : static_cast<long>(s.vertices.size()) + index;
        if (resolved < 0)
          throw InputError(quoted(path) + " " + where + ": face index " + std::to_string(index) +
                           " refers to a vertex before the first one");
        if (resolved > std::numeric_limits<int>::max())
          throw InputError(quoted(path) + " " + where + ": face index " + std::to_string(index) +
                           " is beyond the supported 2^31 vertices");
        q[k] = static_cast<int>(resolved);
      }
      s.quads.push_back(q);
      face_line.push_back(line_no);
    } else if (key == "vn" || key == "vt" || key == "vp" || key == "o" || key == "g" || key == "s" ||
               key == "usemtl" || key == "mtllib") {
      continue;  // normals, texture coordinates, groups and materials do not affect the mesh
    } else if (key == "l" || key == "p") {
      throw InputError(quoted(path) + " " + where + ": '" + key +
                       "' elements (lines or points) are not part of a quad surface; remove them and give "
                       "only the 'v' and 'f' lines of the quads");
    } else {
      throw InputError(quoted(path) + " " + where + ": unknown OBJ line '" + line + "'");
    }
  }
  for (std::size_t f = 0; f < s.quads.size(); ++f)
    for (int v : s.quads[f])
      if (v >= static_cast<int>(s.vertices.size()))
        throw InputError(quoted(path) + " line " + std::to_string(face_line[f]) + ": face index " +
                         std::to_string(v + 1) + " is out of range (the file has " +
                         std::to_string(s.vertices.size()) + " vertices)");
  require_quads(path, s);
  return s;
}

QuadSurface from_polydata(const std::string& path, vtkPolyData* poly) {
  QuadSurface s;
  if (!poly || poly->GetNumberOfPoints() == 0)
    throw InputError(quoted(path) + " is not VTK polydata with points (unreadable or empty file)");
  if (poly->GetNumberOfStrips() > 0)
    throw InputError(quoted(path) + " holds triangle strips; a quad surface holds only quads");
  // Like an OBJ 'l' or 'p' line: edges or points exported with the surface would otherwise be dropped
  // silently.
  const vtkIdType lines = poly->GetNumberOfLines(), verts = poly->GetNumberOfVerts();
  if (lines > 0 || verts > 0) {
    const auto count = [](vtkIdType n, const std::string& what) {
      return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
    };
    const std::string found = lines > 0 && verts > 0
                                  ? count(lines, "line cell") + " and " + count(verts, "vertex cell")
                              : lines > 0 ? count(lines, "line cell")
                                          : count(verts, "vertex cell");
    throw InputError(quoted(path) + " holds " + found + " besides its " +
                     count(poly->GetNumberOfPolys(), "polygon") +
                     "; lines and points are not part of a quad surface: remove them (e.g. ParaView's "
                     "Extract Cells By Type, keeping polygons) and give only the quads");
  }
  const vtkIdType n = poly->GetNumberOfPoints();
  s.vertices.resize(static_cast<std::size_t>(n));
  for (vtkIdType i = 0; i < n; ++i) {
    double p[3];
    poly->GetPoint(i, p);
    s.vertices[std::size_t(i)] = {p[0], p[1], p[2]};
    require_finite(path, "point " + std::to_string(i) + " (0-based)", s.vertices[std::size_t(i)]);
  }
  vtkCellArray* polys = poly->GetPolys();
  vtkIdType npts = 0;
  const vtkIdType* ids = nullptr;
  vtkIdType face = 0;
  for (polys->InitTraversal(); polys->GetNextCell(npts, ids); ++face) {
    if (npts != 4)
      throw InputError(quoted(path) + " face " + std::to_string(face) + " (0-based) has " +
                       std::to_string(npts) + " corners; a quad surface holds only quads (4 corners)");
    std::array<int, 4> q{};
    for (int k = 0; k < 4; ++k) {
      if (ids[k] < 0 || ids[k] >= n)
        throw InputError(quoted(path) + " face " + std::to_string(face) + " (0-based) refers to point " +
                         std::to_string(ids[k]) + ", out of range (the file has " + std::to_string(n) +
                         " points)");
      q[k] = static_cast<int>(ids[k]);
    }
    s.quads.push_back(q);
  }
  require_quads(path, s);
  return s;
}

// A reader's error code or an error it printed says a file is broken (the XML reader reports a cut-off file
// only by printing); VTK's captured explanation says how.
QuadSurface read_vtp(const std::string& path) {
  VtkMessageCapture capture;
  vtkNew<vtkXMLPolyDataReader> reader;
  if (!reader->CanReadFile(path.c_str()))
    throw InputError(quoted(path) + " is not a VTK XML polydata (.vtp) file");
  reader->SetFileName(path.c_str());
  update_xml_reader(reader, path);
  if (reader->GetErrorCode() != 0 || !capture.errors().empty())
    throw InputError(quoted(path) + " could not be read as VTK XML polydata (truncated or corrupt file" +
                     capture.reason() + ")");
  return from_polydata(path, reader->GetOutput());
}

// Bytes of one value of a legacy VTK data type; 0 for a type not known here.
std::size_t legacy_type_size(std::string type) {
  std::transform(type.begin(), type.end(), type.begin(), [](unsigned char c) { return std::tolower(c); });
  if (type == "char" || type == "unsigned_char" || type == "vtktypeint8" || type == "vtktypeuint8") return 1;
  if (type == "short" || type == "unsigned_short" || type == "vtktypeint16" || type == "vtktypeuint16")
    return 2;
  if (type == "int" || type == "unsigned_int" || type == "float" || type == "vtktypeint32" ||
      type == "vtktypeuint32")
    return 4;
  if (type == "long" || type == "unsigned_long" || type == "double" || type == "vtktypeint64" ||
      type == "vtktypeuint64" || type == "vtkidtype")
    return 8;
  return 0;
}

// VTK 9.1's legacy reader crashes (segmentation fault) when a cell section ends early or holds something
// other than an integer: it closes the file and reads on. And a CONNECTIVITY section (file version 5) that
// ends early is read with made-up indices. So the counts of the POINTS and cell sections are checked here
// first, by values (ASCII) or bytes (BINARY); the rest of the file (attributes) is left to VTK.
void require_complete_legacy_sections(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto upper = [](std::string w) {
    std::transform(w.begin(), w.end(), w.begin(), [](unsigned char c) { return std::toupper(c); });
    return w;
  };
  auto number = [](const std::string& text, auto& value) {
    const char* end = text.data() + text.size();
    return !text.empty() && std::from_chars(text.data(), end, value).ptr == end;
  };
  const std::size_t header_end = std::min(bytes.find('\n'), bytes.size());
  const std::size_t v = bytes.substr(0, header_end).find("Version ");
  const int version = v == std::string::npos ? 0 : std::atoi(bytes.c_str() + v + 8);
  std::size_t at = std::min(bytes.find('\n', header_end + 1), bytes.size());  // the end of the title line
  long line = 2;                                                              // the line of `at`
  auto skip_space = [&] {
    for (; at < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[at])); ++at)
      line += bytes[at] == '\n';
  };
  // The words of the next line that holds any (the format, or a keyword line); `at` stays at its end.
  auto next_line = [&] {
    skip_space();
    const std::size_t end = std::min(bytes.find('\n', at), bytes.size());
    std::istringstream text(bytes.substr(at, end - at));
    at = end;
    std::vector<std::string> words;
    for (std::string w; text >> w;) words.push_back(w);
    return words;
  };
  const std::vector<std::string> format = next_line();
  const bool binary = !format.empty() && upper(format[0]) == "BINARY";
  if (!binary && (format.empty() || upper(format[0]) != "ASCII")) return;  // VTK names the header's fault

  // Reads past the values of `type` after a keyword line: `items` of `per_item` values each, as `announced`
  // says ("4 points"). False for a type not known here (VTK's message then).
  auto skip_values = [&](const std::string& section, long long items, int per_item,
                         const std::string& announced, const std::string& type, bool integers) {
    const auto cut_off = [&] {
      return InputError(quoted(path) + ": the file ends inside its " + section +
                        " section, which announces " + announced + ": it was cut off; export it again");
    };
    // More items than bytes cannot be there (and their product could overflow).
    if (items > static_cast<long long>(bytes.size())) throw cut_off();
    const long long count = items * per_item;
    if (binary) {
      const std::size_t size = legacy_type_size(type);
      if (size == 0) return false;
      if (at < bytes.size()) ++at, ++line;  // the keyword line's '\n'; the data follows it at once
      if (static_cast<unsigned long long>(count) > (bytes.size() - at) / size) throw cut_off();
      at += static_cast<std::size_t>(count) * size;
      return true;
    }
    for (long long i = 0; i < count; ++i) {
      skip_space();
      const std::size_t begin = at;
      while (at < bytes.size() && !std::isspace(static_cast<unsigned char>(bytes[at]))) ++at;
      const std::string value = bytes.substr(begin, at - begin);
      if (value.empty()) throw cut_off();
      long long integer = 0;
      double real = 0;
      if (!(integers ? number(value, integer) : parse_double(value, real)))
        throw InputError(quoted(path) + " line " + std::to_string(line) + ": '" + value + "' in its " +
                         section + " section is not " + (integers ? "an integer" : "a number") +
                         "; fix the file or export it again");
      // VTK's reader stops on these with "Unrecognized keyword" and no line.
      if (!integers && !std::isfinite(real))
        throw InputError(quoted(path) + " line " + std::to_string(line) + ": '" + value + "' in its " +
                         section +
                         " section is NaN, infinite or beyond the double range; every coordinate must be a "
                         "finite number");
      // VTK reads a 32-bit type's value into an int, and one beyond it crashed the reader.
      if (integers && legacy_type_size(type) == 4 &&
          (integer < std::numeric_limits<std::int32_t>::min() ||
           integer > std::numeric_limits<std::int32_t>::max()))
        throw InputError(quoted(path) + " line " + std::to_string(line) + ": '" + value + "' in its " +
                         section + " section is beyond the 32-bit integers of its type " + type +
                         "; fix the file or export it again");
    }
    return true;
  };
  for (;;) {
    const std::vector<std::string> words = next_line();
    const std::string keyword = words.empty() ? std::string() : upper(words[0]);
    long long count = 0, size = 0;
    if (keyword == "DATASET") continue;
    if (keyword == "POINTS") {
      if (words.size() < 3 || !number(words[1], count) || count < 0 ||
          !skip_values("POINTS", count, 3, std::to_string(count) + " points", words[2], false))
        return;
      continue;
    }
    if (keyword != "VERTICES" && keyword != "LINES" && keyword != "POLYGONS" && keyword != "TRIANGLE_STRIPS")
      return;  // the end, or attributes: VTK reads them
    if (words.size() < 3 || !number(words[1], count) || !number(words[2], size) || count < 0 || size < 0)
      return;
    if (version < 5) {
      if (!skip_values(keyword, size, 1, std::to_string(size) + " values", "int", true)) return;
      continue;
    }
    for (const std::string part : {"OFFSETS", "CONNECTIVITY"}) {
      const std::vector<std::string> part_words = next_line();
      const long long values = part == "OFFSETS" ? count : size;
      if (part_words.size() < 2 || upper(part_words[0]) != part ||
          !skip_values(keyword + " " + part, values, 1, std::to_string(values) + " values", part_words[1],
                       true))
        return;
    }
  }
}

QuadSurface read_legacy_vtk(const std::string& path) {
  VtkMessageCapture capture;
  vtkNew<vtkPolyDataReader> reader;
  reader->SetFileName(path.c_str());
  if (!reader->IsFilePolyData())
    throw InputError(quoted(path) + " is not a legacy VTK polydata file (DATASET POLYDATA)");
  require_complete_legacy_sections(path);
  reader->Update();
  if (reader->GetErrorCode() != 0 || !capture.errors().empty())
    throw InputError(quoted(path) + " could not be read as legacy VTK polydata (truncated or corrupt file" +
                     capture.reason() + ")");
  return from_polydata(path, reader->GetOutput());
}

}  // namespace

QuadSurface read_quad_surface(const std::string& path) {
  const std::string ext = lower_extension(path);
  if (ext != ".obj" && ext != ".vtp" && ext != ".vtk")
    throw InputError("cannot read quad surface " + quoted(path) + ": " +
                     (ext.empty() ? std::string("no extension") : "unknown extension '" + ext + "'") +
                     "; accepted quad surface formats are .obj, .vtp and .vtk (any case)");
  require_readable_nonempty(path);
  if (ext == ".obj") return read_obj(path);
  if (ext == ".vtp") return read_vtp(path);
  return read_legacy_vtk(path);
}

void write_quad_obj(const std::string& path, const QuadSurface& surface) {
  std::string text = "# quad surface written by hexbite\n";
  char line[128];
  for (const Vec3& p : surface.vertices) {
    std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", p[0], p[1], p[2]);
    text += line;
  }
  for (const auto& q : surface.quads) {
    std::snprintf(line, sizeof line, "f %d %d %d %d\n", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1);
    text += line;
  }
  write_file_atomically(path, text);
}

}  // namespace hexbite
