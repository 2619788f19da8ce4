#include "mesher/ct_surface.h"

#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkCleanPolyData.h>
#include <vtkDataArray.h>
#include <vtkDataArrayRange.h>
#include <vtkFloatArray.h>
#include <vtkFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkMetaImageReader.h>
#include <vtkMetaImageWriter.h>
#include <vtkNIFTIImageHeader.h>
#include <vtkNIFTIImageReader.h>
#include <vtkNIFTIImageWriter.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataConnectivityFilter.h>
#include <vtkSmartPointer.h>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <vector>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/number_format.h"
#include "common/number_parse.h"
#include "common/paths.h"
#include "mesher/dicom_series.h"
#include "mesher/units.h"
#include "mesher/vtk_messages.h"

namespace hexbite {

namespace fs = std::filesystem;

namespace {

// A voxel value or threshold as people write it: -2000, 620.5 (std::to_string gives -2000.000000).
std::string value_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

enum class VolumeFormat { kMetaImage, kNifti };

struct FormatAndExtension {
  VolumeFormat format;
  std::string extension;  // as written in the path, e.g. ".nii.gz"
};

FormatAndExtension volume_format(const std::string& path) {
  std::string lower = path;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  for (const char* ext : {".mha", ".mhd"})
    if (ends_with(lower, ext)) return {VolumeFormat::kMetaImage, path.substr(path.size() - 4)};
  if (ends_with(lower, ".nii.gz")) return {VolumeFormat::kNifti, path.substr(path.size() - 7)};
  if (ends_with(lower, ".nii")) return {VolumeFormat::kNifti, path.substr(path.size() - 4)};
  throw InputError("'" + path +
                   "': unknown volume format; use MetaImage (.mha, .mhd) or NIfTI (.nii, .nii.gz)");
}

// VTK reports reader failures through its output window; an observer keeps the message so that
// it can become part of our own error (naming the file) instead of a stray line on stderr.
struct ErrorCatcher {
  std::string message;
  vtkSmartPointer<vtkCallbackCommand> command = vtkSmartPointer<vtkCallbackCommand>::New();
  ErrorCatcher() {
    command->SetClientData(this);
    command->SetCallback([](vtkObject*, unsigned long, void* client, void* call) {
      auto* self = static_cast<ErrorCatcher*>(client);
      if (self->message.empty() && call) self->message = static_cast<const char*>(call);
    });
  }
  void watch(vtkObject* object) {
    object->AddObserver(vtkCommand::ErrorEvent, command);
    object->AddObserver(vtkCommand::WarningEvent, command);
  }
};

// The explanation in VTK's error text ("ERROR: In ...\nvtkMetaImageReader (0x55...): explanation\n\n"),
// without the class and address, which tell a user nothing.
std::string first_line(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  const auto nl = s.rfind('\n');
  if (nl != std::string::npos) s = s.substr(nl + 1);
  const auto object = s.find("): ");
  return object == std::string::npos ? s : s.substr(object + 3);
}

// MetaIO, inside VTK's MetaImage reader, prints its complaints about a file to std::cerr by itself
// ("ElementDataFile required and not defined.", each twice): kept here while a volume is read, so that they
// become the reason of the one error instead of stray lines before it.
class CerrCapture {
 public:
  CerrCapture() : previous_(std::cerr.rdbuf(text_.rdbuf())) {}
  ~CerrCapture() { std::cerr.rdbuf(previous_); }
  CerrCapture(const CerrCapture&) = delete;
  CerrCapture& operator=(const CerrCapture&) = delete;

  // " (MetaIO: line; line)", each distinct line once, or "" when nothing was printed.
  std::string reason() const {
    std::istringstream in(text_.str());
    std::vector<std::string> seen;
    std::string joined;
    for (std::string line; std::getline(in, line);) {
      while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
      line.erase(0, line.find_first_not_of(" \t"));
      if (line.empty() || std::find(seen.begin(), seen.end(), line) != seen.end()) continue;
      seen.push_back(line);
      joined += (joined.empty() ? "" : "; ") + line;
    }
    return joined.empty() ? std::string() : " (MetaIO: " + joined + ")";
  }
  bool said(const std::string& words) const { return text_.str().find(words) != std::string::npos; }

 private:
  std::ostringstream text_;
  std::streambuf* previous_;
};

vtkSmartPointer<vtkImageData> to_image(const VoxelVolume& volume, int pad, float pad_value) {
  const auto& d = volume.dims;
  const Vec3 h = volume.spacing_xyz();
  auto image = vtkSmartPointer<vtkImageData>::New();
  const int n[3] = {d[0] + 2 * pad, d[1] + 2 * pad, d[2] + 2 * pad};
  image->SetDimensions(n);
  image->SetSpacing(h[0], h[1], h[2]);
  image->SetOrigin(volume.origin[0] - pad * h[0], volume.origin[1] - pad * h[1],
                   volume.origin[2] - pad * h[2]);
  auto values = vtkSmartPointer<vtkFloatArray>::New();
  values->SetName("HU");
  values->SetNumberOfTuples(static_cast<vtkIdType>(n[0]) * n[1] * n[2]);
  float* out = values->GetPointer(0);
  std::fill(out, out + values->GetNumberOfTuples(), pad_value);
  for (int k = 0; k < d[2]; ++k)
    for (int j = 0; j < d[1]; ++j) {
      const float* src = volume.values.data() + (static_cast<std::size_t>(k) * d[1] + j) * d[0];
      float* dst = out + (static_cast<std::size_t>(k + pad) * n[1] + (j + pad)) * n[0] + pad;
      std::copy(src, src + d[0], dst);
    }
  image->GetPointData()->SetScalars(values);
  return image;
}

void check_volume(const VoxelVolume& volume) {
  const auto& d = volume.dims;
  if (d[0] < 1 || d[1] < 1 || d[2] < 1)
    throw InputError("the volume is empty (dimensions " + std::to_string(d[0]) + " x " +
                     std::to_string(d[1]) + " x " + std::to_string(d[2]) + ")");
  if (volume.values.size() != static_cast<std::size_t>(d[0]) * d[1] * d[2])
    throw InputError("the volume holds " + std::to_string(volume.values.size()) +
                     " values, its dimensions need " +
                     std::to_string(static_cast<std::size_t>(d[0]) * d[1] * d[2]));
  const Vec3 h = volume.spacing_xyz();
  for (double s : h)
    if (!(s > 0) || !std::isfinite(s)) throw InputError("the volume's voxel spacing must be positive");
  // An origin or spacing of 1e40 gave a surface with infinite coordinates, written with exit 0; the surface
  // readers refuse coordinates beyond kMaxCoordinateMm, and so does the volume.
  for (int a = 0; a < 3; ++a) {
    const double first = volume.origin[a], last = first + (d[a] - 1) * h[a];
    if (!std::isfinite(first) || !std::isfinite(last) || std::abs(first) > kMaxCoordinateMm ||
        std::abs(last) > kMaxCoordinateMm) {
      char text[256];
      std::snprintf(
          text, sizeof text,
          "the volume's voxels reach %g mm along %c (origin %g mm, spacing %g mm, %d voxels), beyond "
          "the %g mm hexbite reads: its origin or spacing is damaged or in other units",
          std::isfinite(first) && std::abs(first) > std::abs(last) ? first : last, "xyz"[a], first, h[a],
          d[a], kMaxCoordinateMm);
      throw InputError(text);
    }
  }
}

// Reverses the voxel order along `axis` (used for NIfTI orientations that point an axis backwards).
void flip_axis(VoxelVolume& v, int axis) {
  const auto& d = v.dims;
  for (int k = 0; k < d[2]; ++k)
    for (int j = 0; j < d[1]; ++j)
      for (int i = 0; i < d[0]; ++i) {
        int idx[3] = {i, j, k};
        if (idx[axis] >= d[axis] / 2) continue;
        int mirror[3] = {i, j, k};
        mirror[axis] = d[axis] - 1 - idx[axis];
        std::swap(v.values[(static_cast<std::size_t>(k) * d[1] + j) * d[0] + i],
                  v.values[(static_cast<std::size_t>(mirror[2]) * d[1] + mirror[1]) * d[0] + mirror[0]]);
      }
}

// The next "Key = values" line of a MetaImage text header in `in` (lines without '=' are skipped, at most
// 200 lines are read): its key without white space and its values; `line` counts the lines read. False at
// the end.
bool next_header_entry(std::istream& in, int& line, std::string& key, std::istringstream& values) {
  std::string text;
  while (line < 200 && std::getline(in, text)) {
    ++line;
    const auto eq = text.find('=');
    if (eq == std::string::npos) continue;
    key = text.substr(0, eq);
    key.erase(std::remove_if(key.begin(), key.end(), [](unsigned char c) { return std::isspace(c); }),
              key.end());
    values = std::istringstream(text.substr(eq + 1));
    return true;
  }
  return false;
}

// Throws on what makes MetaIO (inside VTK's reader) fail badly instead of refusing: a header key of 255
// characters or more overflows its buffer (the process aborted, "buffer overflow detected"), and an NDims
// below 1 or above 3 made it loop (NDims = -1 hung with a growing memory). Both come from a damaged header
// (zlib data read as header lines once ElementDataFile is lost).
void check_metaimage_header(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  int line = 0;
  std::string key;
  std::istringstream values;
  long long ndims = 0;  // 0 until the header's NDims line
  while (next_header_entry(in, line, key, values)) {
    if (key.size() >= 255)
      throw InputError("volume '" + path + "' line " + std::to_string(line) + ": a header key of " +
                       std::to_string(key.size()) +
                       " characters (MetaImage keys are short words such as DimSize): the header is damaged; "
                       "export the volume again");
    if (key == "NDims") {
      if (!(values >> ndims) || ndims < 1 || ndims > 3)
        throw InputError("volume '" + path + "' line " + std::to_string(line) + ": NDims =" + values.str() +
                         ", but a CT volume has 3 dimensions (NDims = 3): the header is damaged");
    }
    // MetaIO reads a number it cannot parse as the end of the header and then says "DimSize required and
    // not defined", whichever key held it; a fractional DimSize it truncates.
    if (key == "DimSize" || key == "Offset" || key == "Position" || key == "Origin" ||
        key == "ElementSpacing" || key == "ElementSize" || key == "CenterOfRotation") {
      std::vector<double> numbers;
      std::string word;
      bool all_numbers = true;
      while (values >> word) {
        double v = 0;
        all_numbers = all_numbers && parse_double(word, v) && std::isfinite(v) &&
                      (key != "DimSize" || (v >= 1 && std::floor(v) == v));
        numbers.push_back(v);
      }
      if (!all_numbers || (ndims > 0 && static_cast<long long>(numbers.size()) != ndims))
        throw InputError("volume '" + path + "' line " + std::to_string(line) + ": " + key + " =" +
                         values.str() + ": expected " +
                         (ndims > 0 ? std::to_string(ndims) + " " : std::string()) +
                         (key == "DimSize" ? "whole numbers of at least 1" : "finite numbers") +
                         ", one per dimension; fix the header or export the volume again");
    }
    if (key == "ElementDataFile") return;
  }
}

// Throws on the NIfTI-1 headers that crashed VTK's reader (a segmentation fault) instead of being refused:
// a data type it has no reader for (FLOAT128 = 1536, or a code no type has, such as 144) and a dimension
// of size 0 among the first dim[0]. Reads the 348-byte header itself (gzip or plain: zlib's gzread reads
// both); NIfTI-2 and what is no NIfTI-1 header are left to VTK.
void check_nifti_header(const std::string& path) {
  unsigned char h[348] = {};
  gzFile in = gzopen(path.c_str(), "rb");
  if (in == nullptr) return;
  const int got = gzread(in, h, sizeof h);
  gzclose(in);
  if (got != static_cast<int>(sizeof h)) return;
  const auto int32_at = [&](int at, bool swap) {
    std::uint32_t v = 0;
    for (int k = 0; k < 4; ++k) v |= static_cast<std::uint32_t>(h[at + (swap ? 3 - k : k)]) << (8 * k);
    return static_cast<std::int32_t>(v);
  };
  bool swap = false;
  if (int32_at(0, false) != 348) {
    if (int32_at(0, true) != 348) return;
    swap = true;
  }
  const auto int16_at = [&](int at) {
    const int lo = h[at + (swap ? 1 : 0)], hi = h[at + (swap ? 0 : 1)];
    return static_cast<std::int16_t>(static_cast<std::uint16_t>(lo | (hi << 8)));
  };
  // The scalar types of the NIfTI standard that VTK reads; RGB (128) and RGBA (2304) get VTK's message
  // of several components per voxel, 0 VTK's "Unrecognized".
  static const std::set<int> kTypes = {0, 2, 4, 8, 16, 64, 128, 256, 512, 768, 1024, 1280, 2304};
  const int type = int16_at(70);
  if (kTypes.count(type) == 0)
    throw InputError(
        "'" + path + "' has NIfTI datatype " + std::to_string(type) +
        ", not one of the integer or floating-point voxel types hexbite reads (UINT8 2, INT16 4, "
        "INT32 8, FLOAT32 16, FLOAT64 64, INT8 256, UINT16 512, UINT32 768, INT64 1024, UINT64 "
        "1280): export the volume with one of them");
  const int dims = int16_at(40);
  for (int a = 1; a <= std::min(dims, 7); ++a)
    if (int16_at(40 + 2 * a) < 1)
      throw InputError("'" + path + "' has NIfTI dimension " + std::to_string(a) + " of size " +
                       std::to_string(int16_at(40 + 2 * a)) +
                       ": the header is damaged; export the volume again");
}

// VTK's MetaImage reader ignores the grid's direction (TransformMatrix, also spelled Rotation or
// Orientation) and the sign of ElementSpacing, so both are read from the text header here and
// turned into an orientation matrix like NIfTI's qform: a grid stored with a flipped or rotated
// axis would otherwise come out mirrored or in the wrong place without a word.
vtkSmartPointer<vtkMatrix4x4> metaimage_orientation(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::array<double, 9> m = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::array<double, 3> sign = {1, 1, 1};
  int dims = 3;  // NDims comes before the matrix in every MetaImage header
  int line = 0;
  std::string key;
  std::istringstream values;
  while (next_header_entry(in, line, key, values)) {
    if (key == "NDims") {
      if (!(values >> dims) || dims < 1 || dims > 3) dims = 3;  // VTK's reader judges the rest
    } else if (key == "TransformMatrix" || key == "Rotation" || key == "Orientation") {
      m = {1, 0, 0, 0, 1, 0, 0, 0, 1};
      for (int r = 0; r < dims; ++r)
        for (int c = 0; c < dims; ++c)
          if (!(values >> m[3 * r + c]))
            throw InputError("'" + path + "' header line " + std::to_string(line) + ": " + key +
                             " must hold " + std::to_string(dims * dims) + " numbers (the " +
                             std::to_string(dims) + " x " + std::to_string(dims) + " direction matrix)");
    } else if (key == "ElementSpacing") {
      for (int a = 0; a < dims; ++a) {
        double x = 1;
        if (values >> x) sign[a] = x < 0 ? -1 : 1;
      }
    }
    if (key == "ElementDataFile") break;
  }
  auto matrix = vtkSmartPointer<vtkMatrix4x4>::New();
  // MetaImage stores the matrix row by row with the direction of axis i in row i (ITK's
  // convention); the placement is Offset + sum_i index_i spacing_i row_i.
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) matrix->SetElement(r, c, m[3 * c + r] * sign[c]);
  return matrix;
}

// Bytes of voxel data beyond what the header of the MetaImage `path` announces (DimSize times the element
// size), for uncompressed data in the file itself (LOCAL) or in one data file; 0 when it holds no more, or
// when that cannot be told (compressed data, a list of files, an explicit HeaderSize, an unknown type).
// MetaIO reads as much as announced and ignores the rest: a wrong DimSize (a slice count too small) cut the
// bone without a word.
std::uintmax_t metaimage_extra_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string data_file, type, key;
  std::uintmax_t voxels = 1, channels = 1;
  bool compressed = false, known = false;
  int line = 0;
  std::istringstream values;
  while (next_header_entry(in, line, key, values)) {
    if (key == "DimSize") {
      voxels = 1;
      for (long d = 0; values >> d;) voxels *= static_cast<std::uintmax_t>(std::max(d, 0L));
    } else if (key == "ElementNumberOfChannels") {
      values >> channels;
    } else if (key == "ElementType") {
      values >> type;
    } else if (key == "CompressedData") {
      std::string yes;
      values >> yes;
      compressed = yes == "True" || yes == "true";
    } else if (key == "HeaderSize") {
      return 0;
    } else if (key == "ElementDataFile") {
      values >> data_file;
      known = true;
      break;
    }
  }
  const std::map<std::string, std::uintmax_t> sizes = {{"MET_UCHAR", 1}, {"MET_CHAR", 1},  {"MET_USHORT", 2},
                                                       {"MET_SHORT", 2}, {"MET_UINT", 4},  {"MET_INT", 4},
                                                       {"MET_FLOAT", 4}, {"MET_DOUBLE", 8}};
  const auto size = sizes.find(type);
  if (!known || compressed || size == sizes.end() || data_file == "LIST" ||
      data_file.find('%') != std::string::npos)
    return 0;
  const std::uintmax_t announced = voxels * channels * size->second;
  std::error_code ec;
  std::uintmax_t held = 0;
  if (data_file == "LOCAL") {
    const std::streamoff header = in.tellg();
    const std::uintmax_t total = fs::file_size(path, ec);
    if (ec || header < 0 || total < static_cast<std::uintmax_t>(header)) return 0;
    held = total - static_cast<std::uintmax_t>(header);
  } else {
    const fs::path raw = fs::path(path).parent_path() / data_file;
    held = fs::file_size(raw, ec);
    if (ec) return 0;
  }
  return held > announced ? held - announced : 0;
}

// Turns an axis-aligned placement `m` (possibly with reversed axes) of the voxels' index grid, from the
// index origin `org`, into a plain origin, flipping the reversed axes; a rotated grid would need
// resampling, which is the job of a dedicated imaging tool. `what` names the input in messages.
void place_axis_aligned(VoxelVolume& v, const vtkMatrix4x4& m, const double org[3], const std::string& what) {
  // Off-diagonal terms first: a rotation by 90 degrees has zeros on the diagonal and must be called a
  // rotation, not a scaling.
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      if (r != c && std::abs(m.GetElement(r, c)) > 1e-6)
        throw InputError(what +
                         " is stored in a rotated orientation; resample it to an axis-aligned grid first");
  for (int a = 0; a < 3; ++a)
    if (std::abs(std::abs(m.GetElement(a, a)) - 1) > 1e-6)
      throw InputError(what + " has a scaled orientation matrix; it is not supported");
  for (int a = 0; a < 3; ++a) {
    const double t = m.GetElement(a, 3) + m.GetElement(a, a) * org[a];
    if (m.GetElement(a, a) < 0) {
      flip_axis(v, a);
      v.origin[a] = t - (v.dims[a] - 1) * v.axis_spacing[a];
    } else {
      v.origin[a] = t;
    }
  }
}

// A grid of cubes keeps its one spacing (VoxelVolume::spacing) and no per-axis spacing.
void drop_equal_axis_spacing(VoxelVolume& v) {
  v.spacing = v.axis_spacing[0];
  if (std::abs(v.axis_spacing[1] - v.axis_spacing[0]) <= 1e-9 * v.axis_spacing[0] &&
      std::abs(v.axis_spacing[2] - v.axis_spacing[0]) <= 1e-9 * v.axis_spacing[0])
    v.axis_spacing = {};
}

// A DICOM series (mesher/dicom_series.h) as a volume: its slices' placement, in patient coordinates (LPS,
// hexbite's frame), through the same axis-aligned placement as the files' orientation matrices.
VoxelVolume volume_from_dicom(const std::string& folder, VolumeInfo* info, const std::string& wanted) {
  DicomSeries series = read_dicom_series(folder, wanted);
  if (info) {
    info->description = "DICOM series " + (series.series_number.empty() ? "" : series.series_number + " ") +
                        "'" + (series.description.empty() ? series.series_uid : series.description) + "' (" +
                        (series.modality.empty() ? "no modality" : series.modality) + "), " +
                        std::to_string(series.dims[2]) + " slices";
    if (series.other_files > 0)
      info->warnings.push_back(
          "left out " + format_counted(std::size_t(series.other_files), "file") + " of the folder that " +
          (series.other_files == 1 ? "is" : "are") + " no DICOM image" +
          (series.empty_files.empty() ? std::string()
                                      : " (" + std::to_string(series.empty_files.size()) +
                                            " of them empty, '" + series.empty_files.front() +
                                            "' first: a slice cut off by an incomplete copy? then copy the "
                                            "series again)"));
    if (series.modality != "CT")
      info->warnings.push_back("the series' modality is " +
                               (series.modality.empty() ? std::string("not given") : series.modality) +
                               ", not CT: the threshold is in its own units, not Hounsfield units");
  }
  if (info) info->length_unit = "mm";  // DICOM's patient frame is in mm
  VoxelVolume v;
  v.dims = series.dims;
  v.values = std::move(series.values);
  v.axis_spacing = {series.spacing[0], series.spacing[1], series.spacing[2]};
  auto m = vtkSmartPointer<vtkMatrix4x4>::New();
  for (int r = 0; r < 3; ++r) {
    for (int a = 0; a < 3; ++a) m->SetElement(r, a, series.axes[a][r]);
    m->SetElement(r, 3, series.first[r]);
  }
  const double org[3] = {0, 0, 0};
  place_axis_aligned(v, *m, org, "DICOM series '" + folder + "'");
  drop_equal_axis_spacing(v);
  return v;
}

}  // namespace

VoxelVolume read_volume(const std::string& path, VolumeInfo* info, const std::string& dicom_series) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return volume_from_dicom(path, info, dicom_series);
  require_regular_file(path, "volume file");
  if (!dicom_series.empty())
    throw InputError("'" + path + "' is a volume file, not a folder of DICOM slices: a DICOM series ('" +
                     dicom_series + "') is chosen only in a folder; leave it out");
  // One file of a DICOM series (the preamble's "DICM" at byte 128), given instead of its folder.
  if (has_dicom_preamble(path)) {
    const fs::path folder = fs::path(path).has_parent_path() ? fs::path(path).parent_path() : fs::path(".");
    throw InputError("'" + path + "' is one DICOM file (a slice of a series); give the folder that holds " +
                     "the series: '" + folder.string() + "'");
  }
  const FormatAndExtension fmt = volume_format(path);

  ErrorCatcher errors;
  const VtkMessageCapture muted;  // VTK's logger prints a failed pipeline request in colour by itself
  const CerrCapture metaio;
  vtkSmartPointer<vtkImageData> image;
  vtkSmartPointer<vtkMatrix4x4> orientation;
  double slope = 1, intercept = 0;
  double length_scale = 1;  // to millimetres
  if (fmt.format == VolumeFormat::kMetaImage) {
    auto reader = vtkSmartPointer<vtkMetaImageReader>::New();
    errors.watch(reader);
    check_metaimage_header(path);
    if (!reader->CanReadFile(path.c_str()))
      throw InputError("'" + path + "' is not a readable MetaImage file (header missing or malformed)" +
                       metaio.reason());
    reader->SetFileName(path.c_str());
    reader->Update();
    // A file cut off in its voxel data is read without an error: MetaIO only prints that it got less than
    // the header announced, and the missing voxels would make half a bone.
    if (metaio.said("data not read completely"))
      throw InputError("volume '" + path +
                       "' is cut off: it holds less voxel data than its header announces" + metaio.reason() +
                       "; export or download it again");
    if (const std::uintmax_t extra = metaimage_extra_bytes(path))
      throw InputError("volume '" + path + "' holds " + std::to_string(extra) +
                       " bytes of voxel data more than its header announces (DimSize, ElementType); "
                       "correct the header, or export the volume again");
    image = reader->GetOutput();
    orientation = metaimage_orientation(path);
  } else {
    auto reader = vtkSmartPointer<vtkNIFTIImageReader>::New();
    errors.watch(reader);
    check_nifti_header(path);
    if (!reader->CanReadFile(path.c_str()))
      throw InputError("'" + path + "' is not a readable NIfTI file (header missing or malformed)");
    reader->SetFileName(path.c_str());
    reader->Update();
    image = reader->GetOutput();
    // NIfTI stores the grid's placement in the qform (preferred, rigid) or sform matrix; VTK leaves
    // the image origin at zero and hands the matrix over separately.
    orientation = reader->GetQFormMatrix() ? reader->GetQFormMatrix() : reader->GetSFormMatrix();
    if (reader->GetRescaleSlope() != 0) {
      slope = reader->GetRescaleSlope();
      intercept = reader->GetRescaleIntercept();
    }
    // NIfTI may give lengths in metres or micrometres (xyzt_units); hexbite works in millimetres.
    if (vtkNIFTIImageHeader* header = reader->GetNIFTIHeader()) {
      std::string unit;
      switch (header->GetXYZTUnits() & 0x07) {
        case vtkNIFTIImageHeader::UnitsMeter:
          length_scale = 1000;
          unit = "m";
          break;
        case vtkNIFTIImageHeader::UnitsMicron:
          length_scale = 0.001;
          unit = "um";
          break;
        case vtkNIFTIImageHeader::UnitsMM:
          unit = "mm";
          break;
        default:
          break;  // unknown (0): taken as millimetres
      }
      if (info) info->length_unit = unit;
    }
  }
  if (!errors.message.empty() || !image || !image->GetPointData()->GetScalars())
    throw InputError("cannot read volume '" + path + "'" +
                     (errors.message.empty() ? std::string() : ": " + first_line(errors.message)) +
                     metaio.reason());
  vtkDataArray* scalars = image->GetPointData()->GetScalars();
  if (scalars->GetNumberOfComponents() != 1)
    throw InputError("volume '" + path + "' has " + std::to_string(scalars->GetNumberOfComponents()) +
                     " components per voxel; a CT volume has one");

  VoxelVolume v;
  int dims[3];
  image->GetDimensions(dims);
  v.dims = {dims[0], dims[1], dims[2]};
  const double* sp = image->GetSpacing();
  double org[3] = {image->GetOrigin()[0], image->GetOrigin()[1], image->GetOrigin()[2]};
  v.origin = {org[0], org[1], org[2]};
  if (fmt.format == VolumeFormat::kMetaImage) {
    // MetaImage: the Offset is the first voxel's position, the direction applies from there.
    for (int a = 0; a < 3; ++a) {
      orientation->SetElement(a, 3, org[a]);
      org[a] = 0;
    }
  }
  v.axis_spacing = {std::abs(sp[0]), std::abs(sp[1]), std::abs(sp[2])};
  v.spacing = v.axis_spacing[0];
  const vtkIdType n = scalars->GetNumberOfTuples();
  if (n != static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2] || n == 0)
    throw InputError("volume '" + path + "' holds no voxels or fewer than its header announces");
  v.values.resize(static_cast<std::size_t>(n));
  for (vtkIdType i = 0; i < n; ++i) {
    const double value = scalars->GetComponent(i, 0) * slope + intercept;
    v.values[static_cast<std::size_t>(i)] = static_cast<float>(value);
  }

  if (orientation) place_axis_aligned(v, *orientation, org, "volume '" + path + "'");
  if (length_scale != 1) {
    for (int a = 0; a < 3; ++a) {
      v.origin[a] *= length_scale;
      v.axis_spacing[a] *= length_scale;
    }
  }
  drop_equal_axis_spacing(v);
  return v;
}

void write_volume(const std::string& path, const VoxelVolume& volume) {
  const FormatAndExtension fmt = volume_format(path);
  check_volume(volume);
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(dir))
    throw InputError("cannot write '" + path + "': directory '" + dir.string() +
                     "' does not exist; create it first");
  // The temporary name keeps the whole extension (".nii.gz"), from which the VTK writers choose
  // the format and the compression.
  const std::string base = target.filename().string();
  const std::string stem = base.substr(0, base.size() - fmt.extension.size());
  const fs::path tmp = temporary_path_beside(path, fmt.extension);
  // A .mhd header refers to a separate data file, written straight to its final name beside it.
  const fs::path raw = dir / (stem + ".zraw");

  auto image = to_image(volume, 0, 0.0f);
  bool write_failed = false;
  ErrorCatcher errors;
  const VtkMessageCapture muted;
  if (fmt.format == VolumeFormat::kMetaImage) {
    auto writer = vtkSmartPointer<vtkMetaImageWriter>::New();
    errors.watch(writer);
    writer->SetInputData(image);
    writer->SetCompression(true);
    writer->SetFileName(tmp.c_str());
    if (fmt.extension != ".mha" && fmt.extension != ".MHA") writer->SetRAWFileName(raw.c_str());
    // MetaIO tells a failed write (a full disk: "file stream is fail after write") only on standard error,
    // and the cut-off file was kept with exit 0.
    const CerrCapture metaio;
    writer->Write();
    write_failed = metaio.said("fail");
  } else {
    // The grid's placement goes into the qform; VTK's NIfTI writer ignores the image origin.
    auto qform = vtkSmartPointer<vtkMatrix4x4>::New();
    for (int a = 0; a < 3; ++a) qform->SetElement(a, 3, volume.origin[a]);
    image->SetOrigin(0, 0, 0);
    auto writer = vtkSmartPointer<vtkNIFTIImageWriter>::New();
    errors.watch(writer);
    writer->SetInputData(image);
    writer->SetQFormMatrix(qform);
    // The header states millimetres: with xyzt_units 0 (VTK's default) other tools, and hexbite's own
    // reader, have to guess the unit.
    auto header = vtkSmartPointer<vtkNIFTIImageHeader>::New();
    header->SetXYZTUnits(vtkNIFTIImageHeader::UnitsMM);
    writer->SetNIFTIHeader(header);
    writer->SetFileName(tmp.c_str());
    writer->Write();
  }
  std::error_code ec;
  if (!errors.message.empty() || !fs::exists(tmp) || write_failed) {
    fs::remove(tmp, ec);
    if (fmt.extension == ".mhd" || fmt.extension == ".MHD") fs::remove(raw, ec);
    // VTK's writers add ", removing incomplete file .NAME.tmpPID.nii": the temporary name means nothing to
    // the user, whose file of that name is untouched.
    std::string reason = first_line(errors.message);
    reason = reason.substr(0, reason.find(", removing incomplete file"));
    if (write_failed) reason = std::string(kWriteFailed) + ": " + kWriteAdvice;
    throw RunError("cannot write volume '" + path + "'" + (reason.empty() ? std::string() : ": " + reason));
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    std::error_code ignored;  // not ec, which a successful remove clears
    fs::remove(tmp, ignored);
    throw RunError(replace_refused(path, ec));
  }
}

TriSurface surface_from_volume(const VoxelVolume& volume, double threshold, CtExtraction* dropped) {
  check_volume(volume);
  if (!std::isfinite(threshold)) throw InputError("the threshold must be a finite number");
  // Voxels without a value (NaN, as some exporters store outside the field of view) take no part
  // in the range.
  float lo_value = std::numeric_limits<float>::infinity(), hi_value = -lo_value;
  for (float x : volume.values)
    if (std::isfinite(x)) {
      lo_value = std::min(lo_value, x);
      hi_value = std::max(hi_value, x);
    }
  const float* lo = &lo_value;
  const float* hi = &hi_value;
  if (!(*hi > threshold))
    throw InputError("nothing in the volume exceeds the threshold " + value_text(threshold) +
                     " (values range from " + value_text(*lo) + " to " + value_text(*hi) +
                     "); choose a lower threshold");
  if (!(*lo < threshold))
    throw InputError("every voxel of the volume is at or above the threshold " + value_text(threshold) +
                     " (values range from " + value_text(*lo) + " to " + value_text(*hi) +
                     "): the surface would be the box of the whole scan, not the bone; choose a higher "
                     "threshold");
  // One voxel of background around the grid closes the iso-surface where the object touches the
  // border of the scan, so the result always bounds a solid.
  const float background = *lo;
  auto image = to_image(volume, 1, background);
  // So are voxels without a value: the contour through one (a NaN) had NaN coordinates.
  auto* hu = static_cast<vtkFloatArray*>(image->GetPointData()->GetScalars());
  for (float& x : vtk::DataArrayValueRange<1>(hu))
    if (!std::isfinite(x)) x = background;

  auto contour = vtkSmartPointer<vtkFlyingEdges3D>::New();
  contour->SetInputData(image);
  contour->SetValue(0, threshold);
  contour->ComputeNormalsOff();
  contour->ComputeGradientsOff();
  contour->ComputeScalarsOff();
  contour->InterpolateAttributesOff();

  // Inner surfaces (marrow cavities below the threshold) and loose fragments are separate
  // components; the bone's outer surface is the largest one.
  auto largest = vtkSmartPointer<vtkPolyDataConnectivityFilter>::New();
  largest->SetInputConnection(contour->GetOutputPort());
  largest->SetExtractionModeToLargestRegion();

  if (dropped) {
    *dropped = CtExtraction{};
    auto all = vtkSmartPointer<vtkPolyDataConnectivityFilter>::New();
    all->SetInputConnection(contour->GetOutputPort());
    all->SetExtractionModeToAllRegions();
    all->ColorRegionsOn();
    all->Update();
    vtkPolyData* pieces = all->GetOutput();
    const int regions = all->GetNumberOfExtractedRegions();
    // ColorRegions labels the points; every point of a triangle is in the triangle's region.
    vtkDataArray* region_of_point = pieces->GetPointData()->GetArray("RegionId");
    if (regions > 1 && region_of_point) {
      std::vector<double> six_volume(static_cast<std::size_t>(regions), 0.0);
      std::vector<vtkIdType> cells(static_cast<std::size_t>(regions), 0);
      vtkCellArray* tris = pieces->GetPolys();
      vtkIdType npts = 0;
      const vtkIdType* ids = nullptr;
      for (tris->InitTraversal(); tris->GetNextCell(npts, ids);) {
        if (npts != 3) continue;
        const auto r = static_cast<std::size_t>(region_of_point->GetComponent(ids[0], 0));
        if (r >= six_volume.size()) continue;
        double a[3], b[3], c[3];
        pieces->GetPoint(ids[0], a);
        pieces->GetPoint(ids[1], b);
        pieces->GetPoint(ids[2], c);
        six_volume[r] += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                         a[2] * (b[0] * c[1] - b[1] * c[0]);
        ++cells[r];
      }
      // The kept piece is the one with the most triangles, as vtkPolyDataConnectivityFilter picks it.
      const auto kept =
          static_cast<std::size_t>(std::max_element(cells.begin(), cells.end()) - cells.begin());
      dropped->kept_mm3 = std::abs(six_volume[kept]) / 6;
      for (std::size_t r = 0; r < six_volume.size(); ++r) {
        if (r == kept || cells[r] == 0) continue;
        const double v = std::abs(six_volume[r]) / 6;
        if ((six_volume[r] > 0) == (six_volume[kept] > 0)) {
          ++dropped->dropped_bodies;
          dropped->largest_dropped_body_mm3 = std::max(dropped->largest_dropped_body_mm3, v);
        } else {
          ++dropped->dropped_cavities;
          dropped->largest_dropped_cavity_mm3 = std::max(dropped->largest_dropped_cavity_mm3, v);
        }
      }
    }
  }

  auto clean = vtkSmartPointer<vtkCleanPolyData>::New();
  clean->SetInputConnection(largest->GetOutputPort());
  clean->PointMergingOn();
  clean->SetTolerance(0.0);
  clean->ConvertPolysToLinesOff();
  clean->ConvertLinesToPointsOff();
  clean->ConvertStripsToPolysOff();
  clean->Update();
  vtkPolyData* poly = clean->GetOutput();

  TriSurface s;
  s.vertices.resize(static_cast<std::size_t>(poly->GetNumberOfPoints()));
  for (vtkIdType i = 0; i < poly->GetNumberOfPoints(); ++i) {
    double p[3];
    poly->GetPoint(i, p);
    s.vertices[static_cast<std::size_t>(i)] = {p[0], p[1], p[2]};
  }
  vtkCellArray* polys = poly->GetPolys();
  s.triangles.reserve(static_cast<std::size_t>(polys->GetNumberOfCells()));
  vtkIdType npts = 0;
  const vtkIdType* ids = nullptr;
  for (polys->InitTraversal(); polys->GetNextCell(npts, ids);) {
    if (npts != 3) continue;
    const std::array<int, 3> t = {static_cast<int>(ids[0]), static_cast<int>(ids[1]),
                                  static_cast<int>(ids[2])};
    // Merging coincident points (an iso-value met exactly at a grid node) can collapse a
    // triangle to an edge; it has no area and no place in a closed surface.
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    s.triangles.push_back(t);
  }
  if (s.triangles.empty())
    throw InputError("the iso-surface at threshold " + value_text(threshold) + " is empty");

  // Marching cubes orients all triangles consistently; the sign of the enclosed volume tells
  // whether that orientation points out of the solid.
  double six_volume = 0;
  for (const auto& t : s.triangles) {
    const Vec3& a = s.vertices[t[0]];
    const Vec3& b = s.vertices[t[1]];
    const Vec3& c = s.vertices[t[2]];
    six_volume += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                  a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  if (six_volume < 0)
    for (auto& t : s.triangles) std::swap(t[1], t[2]);
  return s;
}

std::vector<std::string> describe_dropped(const CtExtraction& dropped, double threshold) {
  std::vector<std::string> out;
  const double kept = std::max(dropped.kept_mm3, 1e-300);
  char buf[600];
  if (dropped.dropped_bodies > 0) {
    std::snprintf(
        buf, sizeof buf,
        "kept only the largest piece (%.2f cm^3); dropped %d separate piece(s) at threshold %g, the "
        "largest enclosing %.2f cm^3 (%.1f%% of the kept one). If that is bone (a second bone, a "
        "fragment), crop the volume to one bone or raise the threshold; small ones are usually noise",
        dropped.kept_mm3 / 1000, dropped.dropped_bodies, threshold, dropped.largest_dropped_body_mm3 / 1000,
        100 * dropped.largest_dropped_body_mm3 / kept);
    out.push_back(buf);
  }
  if (dropped.dropped_cavities > 0) {
    std::snprintf(buf, sizeof buf,
                  "filled %d enclosed cavit%s below threshold %g (the largest %.2f cm^3, %.1f%% of the kept "
                  "piece): the surface is the outer wall only",
                  dropped.dropped_cavities, dropped.dropped_cavities == 1 ? "y" : "ies", threshold,
                  dropped.largest_dropped_cavity_mm3 / 1000, 100 * dropped.largest_dropped_cavity_mm3 / kept);
    out.push_back(buf);
  }
  return out;
}

void rescale_volume_units(VoxelVolume& volume, const std::string& stated_unit, const std::string& unit) {
  const double factor = unit_to_mm(unit) / stated_unit_to_mm(stated_unit);
  for (int a = 0; a < 3; ++a) {
    volume.origin[a] *= factor;
    volume.axis_spacing[a] *= factor;
  }
  volume.spacing *= factor;
}

}  // namespace hexbite
