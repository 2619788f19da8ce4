#include "mesher/dicom_series.h"

#include <gdcmAttribute.h>
#include <gdcmImageReader.h>
#include <gdcmImageWriter.h>
#include <gdcmTrace.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <system_error>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/number_format.h"

namespace hexbite {
namespace {

namespace fs = std::filesystem;

// A tag's text without DICOM's padding (trailing spaces and NULs); empty when the tag is missing.
std::string tag_text(const gdcm::DataSet& ds, uint16_t group, uint16_t element) {
  const gdcm::Tag tag(group, element);
  if (!ds.FindDataElement(tag)) return {};
  const gdcm::ByteValue* bytes = ds.GetDataElement(tag).GetByteValue();
  if (bytes == nullptr) return {};
  std::string text(bytes->GetPointer(), bytes->GetLength());
  while (!text.empty() && (text.back() == ' ' || text.back() == '\0')) text.pop_back();
  while (!text.empty() && text.front() == ' ') text.erase(text.begin());
  return text;
}

// The numbers of a multi-valued decimal tag ("0.5\0.5"); empty when missing or not all numbers.
std::vector<double> tag_numbers(const gdcm::DataSet& ds, uint16_t group, uint16_t element) {
  std::vector<double> numbers;
  std::stringstream in(tag_text(ds, group, element));
  std::string item;
  while (std::getline(in, item, '\\')) {
    char* end = nullptr;
    const double x = std::strtod(item.c_str(), &end);
    if (end == item.c_str() || !std::isfinite(x)) return {};
    numbers.push_back(x);
  }
  return numbers;
}

struct Slice {
  std::string file;
  std::array<int, 2> size{};              // columns, rows
  std::array<double, 2> pixel_spacing{};  // between columns (along a row), between rows, mm
  Vec3 position{};
  Vec3 row{}, column{};  // directions of increasing column and row index
  double along = 0;      // position along the normal
  std::vector<float> values;
};

double dot3(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

Vec3 cross3(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

std::string mm(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g mm", x);
  return text;
}

// The stored pixels of one frame as floats, rescaled by the slice's slope and intercept.
template <typename T>
void rescale(const std::vector<char>& buffer, double slope, double intercept, std::vector<float>& out) {
  const std::size_t n = buffer.size() / sizeof(T);
  out.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    T stored;
    std::memcpy(&stored, buffer.data() + i * sizeof(T), sizeof(T));
    out[i] = static_cast<float>(double(stored) * slope + intercept);
  }
}

// Reads `file` as a DICOM image slice; false when it is no DICOM image (another file in the folder).
// The tags that tell the series of a slice apart.
struct SeriesTags {
  std::string uid, number, modality, description;
};

// Throws when a file with the DICOM preamble ("DICM" at byte 128) ends inside its File Meta Information
// (group 0002, always explicit VR little endian): GDCM asserted on such a file and the process aborted
// (exit 134), where an interrupted copy cut a slice after 160 to 300 bytes. Hand-written: GDCM has no check
// that does not abort. Files without the preamble are left to GDCM.
void require_complete_meta_group(const std::string& file, const std::string& where) {
  std::ifstream in(file, std::ios::binary);
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(file, ec);
  if (ec || head.size() < 132 || head.compare(128, 4, "DICM") != 0) return;
  const auto byte = [&](std::size_t at) {
    return static_cast<unsigned>(static_cast<unsigned char>(head[at]));
  };
  const auto cut = [&] {
    return InputError(where + " is cut off in its header (" + std::to_string(size) +
                      " bytes; an incomplete copy?); copy the series again");
  };
  std::size_t at = 132;
  while (true) {
    if (at + 8 > head.size()) {
      if (at + 8 > size) throw cut();
      return;  // a meta group longer than what was read: GDCM reads it
    }
    if ((byte(at) | byte(at + 1) << 8) != 0x0002) return;  // the meta group ends here
    const std::string vr = head.substr(at + 4, 2);
    unsigned long long length = 0;
    std::size_t header = 8;
    if (vr == "OB" || vr == "OW" || vr == "OF" || vr == "SQ" || vr == "UT" || vr == "UN") {
      if (at + 12 > head.size()) {
        if (at + 12 > size) throw cut();
        return;  // as above
      }
      length = byte(at + 8) | byte(at + 9) << 8 | byte(at + 10) << 16 |
               static_cast<unsigned long long>(byte(at + 11)) << 24;
      header = 12;
    } else {
      length = byte(at + 6) | byte(at + 7) << 8;
    }
    if (at + header + length > size) throw cut();
    at += header + static_cast<std::size_t>(length);
  }
}

bool read_slice(const std::string& file, const std::string& folder, Slice& slice, SeriesTags& tags) {
  require_complete_meta_group(
      file, "DICOM series '" + folder + "': file '" + fs::path(file).filename().string() + "'");
  gdcm::ImageReader reader;
  reader.SetFileName(file.c_str());
  // GDCM reads a file cut off in its pixel data (an interrupted copy) and fills the missing pixels; it says
  // so only as a warning, which is caught here.
  std::ostringstream warnings;
  gdcm::Trace::SetWarningStream(warnings);
  gdcm::Trace::SetWarning(true);
  const bool read = reader.Read();
  gdcm::Trace::SetWarning(false);
  gdcm::Trace::SetWarningStream(std::cerr);
  if (!read) return false;
  const gdcm::Image& image = reader.GetImage();
  const gdcm::DataSet& ds = reader.GetFile().GetDataSet();
  const std::string where =
      "DICOM series '" + folder + "': file '" + fs::path(file).filename().string() + "'";
  if (warnings.str().find("Incomplete Pixel Data") != std::string::npos)
    throw InputError(where + " is cut off in its pixel data (an incomplete copy?); copy the series again");
  if (image.GetNumberOfDimensions() == 3 && image.GetDimension(2) > 1)
    throw InputError(where + " holds " + std::to_string(image.GetDimension(2)) +
                     " frames (an enhanced multi-frame image), which hexbite does not read; export the "
                     "series as one file per slice");
  if (image.GetPixelFormat().GetSamplesPerPixel() != 1)
    throw InputError(where + " has " + std::to_string(image.GetPixelFormat().GetSamplesPerPixel()) +
                     " samples per pixel (a colour image); a CT slice has one");
  tags.uid = tag_text(ds, 0x0020, 0x000e);
  tags.number = tag_text(ds, 0x0020, 0x0011);
  tags.modality = tag_text(ds, 0x0008, 0x0060);
  tags.description = tag_text(ds, 0x0008, 0x103e);
  const std::vector<double> position = tag_numbers(ds, 0x0020, 0x0032);
  const std::vector<double> orientation = tag_numbers(ds, 0x0020, 0x0037);
  const std::vector<double> spacing = tag_numbers(ds, 0x0028, 0x0030);
  if (position.size() != 3 || orientation.size() != 6)
    throw InputError(where +
                     " has no Image Position (Patient) or Image Orientation (Patient), so the slice "
                     "cannot be placed; hexbite reads CT series whose slices carry both");
  if (spacing.size() != 2 || !(spacing[0] > 0) || !(spacing[1] > 0))
    throw InputError(where + " has no valid Pixel Spacing (0028,0030), so its size in mm is unknown");
  slice.file = file;
  slice.size = {int(image.GetDimension(0)), int(image.GetDimension(1))};
  slice.pixel_spacing = {spacing[1], spacing[0]};  // the tag gives the row spacing first
  slice.position = {position[0], position[1], position[2]};
  slice.row = {orientation[0], orientation[1], orientation[2]};
  slice.column = {orientation[3], orientation[4], orientation[5]};

  std::vector<char> buffer(image.GetBufferLength());
  if (!image.GetBuffer(buffer.data()))
    throw InputError(where +
                     ": its pixel data cannot be decoded (a damaged file, or a compression GDCM "
                     "lacks); export the series uncompressed");
  const double slope = image.GetSlope(), intercept = image.GetIntercept();
  switch (image.GetPixelFormat().GetScalarType()) {
    case gdcm::PixelFormat::UINT8:
      rescale<uint8_t>(buffer, slope, intercept, slice.values);
      break;
    case gdcm::PixelFormat::INT8:
      rescale<int8_t>(buffer, slope, intercept, slice.values);
      break;
    case gdcm::PixelFormat::UINT16:
      rescale<uint16_t>(buffer, slope, intercept, slice.values);
      break;
    case gdcm::PixelFormat::INT16:
      rescale<int16_t>(buffer, slope, intercept, slice.values);
      break;
    case gdcm::PixelFormat::UINT32:
      rescale<uint32_t>(buffer, slope, intercept, slice.values);
      break;
    case gdcm::PixelFormat::INT32:
      rescale<int32_t>(buffer, slope, intercept, slice.values);
      break;
    case gdcm::PixelFormat::FLOAT32:
      rescale<float>(buffer, slope, intercept, slice.values);
      break;
    case gdcm::PixelFormat::FLOAT64:
      rescale<double>(buffer, slope, intercept, slice.values);
      break;
    default:
      throw InputError(where + " stores its pixels as " +
                       std::string(image.GetPixelFormat().GetScalarTypeAsString()) +
                       ", which hexbite does not read; export the series with 8-, 16- or 32-bit pixels");
  }
  if (slice.values.size() != std::size_t(slice.size[0]) * std::size_t(slice.size[1]))
    throw InputError(where + " holds " + std::to_string(slice.values.size()) +
                     " pixels where its header "
                     "announces " +
                     std::to_string(slice.size[0]) + " x " + std::to_string(slice.size[1]));
  return true;
}

// 128 bits of FNV-1a (two differently seeded 64-bit states), as the decimal of a UID under the 2.25 root
// (ISO/IEC 9834-8: a UID from a 128-bit number); deterministic, unlike GDCM's generator. The volume is
// hashed once, and each UID goes on from that state with a few bytes of its own.
struct ContentHash {
  uint64_t a = 14695981039346656037ULL, b = 0x9e3779b97f4a7c15ULL;
  void add(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) {
      a = (a ^ p[i]) * 1099511628211ULL;
      b = (b ^ p[i]) * 1099511628211ULL;
    }
  }
  std::string uid(const std::string& what) const {
    ContentHash h = *this;
    h.add(what.data(), what.size());
    unsigned __int128 n = (static_cast<unsigned __int128>(h.a) << 64) | h.b;
    std::string digits;
    do {
      digits.insert(digits.begin(), char('0' + int(n % 10)));
      n /= 10;
    } while (n != 0);
    return "2.25." + digits;
  }
};

void put_text(gdcm::DataSet& ds, uint16_t group, uint16_t element, gdcm::VR vr, std::string value) {
  if (value.size() % 2 != 0) value.push_back(vr == gdcm::VR::UI ? '\0' : ' ');
  gdcm::DataElement de(gdcm::Tag(group, element));
  de.SetVR(vr);
  de.SetByteValue(value.data(), static_cast<uint32_t>(value.size()));
  ds.Replace(de);
}

// GDCM prints its doubts (about files that are no DICOM images, tags it fills in) on standard error; the
// reader counts other files and names real problems itself.
void quiet_gdcm() {
  gdcm::Trace::SetWarning(false);
  gdcm::Trace::SetError(false);
  gdcm::Trace::SetDebug(false);
}

}  // namespace

bool has_dicom_preamble(const std::string& file) {
  char magic[4] = {};
  std::ifstream in(file, std::ios::binary);
  in.seekg(128).read(magic, 4);
  return in.gcount() == 4 && std::string(magic, 4) == "DICM";
}

DicomSeries read_dicom_series(const std::string& folder, const std::string& wanted) {
  if (!fs::is_directory(folder)) throw InputError("DICOM series '" + folder + "' is not a folder");
  quiet_gdcm();
  std::vector<std::string> files;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder))
    if (entry.is_regular_file()) files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());

  struct Series {
    SeriesTags tags;
    std::vector<Slice> slices;
  };
  std::map<std::string, Series> series;
  DicomSeries out;
  for (const std::string& file : files) {
    Slice slice;
    SeriesTags tags;
    if (!read_slice(file, folder, slice, tags)) {
      ++out.other_files;
      std::error_code ec;
      if (fs::file_size(file, ec) == 0 && !ec) out.empty_files.push_back(fs::path(file).filename().string());
      continue;
    }
    Series& s = series[tags.uid];
    s.tags = tags;
    s.slices.push_back(std::move(slice));
  }
  if (series.empty())
    throw InputError("'" + folder + "' holds no DICOM image (" + format_counted(files.size(), "file") +
                     " read); give the folder of a CT series, one file per slice");
  // "number 3, 'BONE 0.6', 212 slices, UID 2.25.1234" for each series, for the messages below.
  auto listed = [&](const std::vector<Series*>& list) {
    std::string text;
    for (const Series* s : list)
      text += std::string(text.empty() ? "" : "; ") + "number " +
              (s->tags.number.empty() ? "(none)" : s->tags.number) + ", '" +
              (s->tags.description.empty() ? s->tags.modality : s->tags.description) + "', " +
              format_counted(s->slices.size(), "slice") + ", UID " + s->tags.uid;
    return text;
  };
  std::vector<Series*> all, chosen;
  for (auto& [uid, s] : series) {
    all.push_back(&s);
    if (!wanted.empty() && (uid == wanted || s.tags.number == wanted || s.tags.description == wanted))
      chosen.push_back(&s);
  }
  const std::string choose =
      "choose one by its number, description or UID (surface from-ct --series, or series: in a scenario's "
      "ct)";
  if (wanted.empty() && series.size() > 1)
    throw InputError("'" + folder + "' holds " + std::to_string(series.size()) + " DICOM series (" +
                     listed(all) + "); " + choose);
  if (!wanted.empty() && chosen.empty())
    throw InputError("'" + folder + "' holds no DICOM series numbered, described or identified as '" +
                     wanted + "'; its series: " + listed(all));
  if (chosen.size() > 1)
    throw InputError("'" + folder + "' holds " + std::to_string(chosen.size()) + " DICOM series that '" +
                     wanted + "' names (" + listed(chosen) + "); choose one by its UID");
  Series& s = chosen.empty() ? series.begin()->second : *chosen.front();
  const std::string uid = s.tags.uid;
  std::vector<Slice>& slices = s.slices;
  const std::string where = "DICOM series '" + folder + "'";
  if (slices.size() < 2) throw InputError(where + " has one slice; a volume needs at least two");

  const Slice& first = slices.front();
  auto name = [](const Slice& sl) { return "'" + fs::path(sl.file).filename().string() + "'"; };
  for (const Slice& sl : slices) {
    if (sl.size != first.size)
      throw InputError(where + ": file " + name(sl) + " is " + std::to_string(sl.size[0]) + " x " +
                       std::to_string(sl.size[1]) + " pixels, file " + name(first) + " " +
                       std::to_string(first.size[0]) + " x " + std::to_string(first.size[1]) +
                       "; the slices of a volume have one size");
    for (int a = 0; a < 3; ++a)
      if (std::abs(sl.row[a] - first.row[a]) > 1e-4 || std::abs(sl.column[a] - first.column[a]) > 1e-4)
        throw InputError(where + ": file " + name(sl) + " is oriented otherwise than file " + name(first) +
                         " (Image Orientation (Patient)); the slices of a volume are parallel");
    for (int a = 0; a < 2; ++a)
      if (std::abs(sl.pixel_spacing[a] - first.pixel_spacing[a]) > 1e-4 * first.pixel_spacing[a])
        throw InputError(where + ": file " + name(sl) + " has another Pixel Spacing than file " +
                         name(first));
  }
  const Vec3 normal = cross3(first.row, first.column);
  if (std::abs(dot3(normal, normal) - 1) > 1e-3 || std::abs(dot3(first.row, first.column)) > 1e-3)
    throw InputError(where + ": the Image Orientation (Patient) of file " + name(first) +
                     " is not two perpendicular unit vectors");
  for (Slice& sl : slices) sl.along = dot3(sl.position, normal);
  std::sort(slices.begin(), slices.end(), [](const Slice& a, const Slice& b) { return a.along < b.along; });

  std::vector<double> gaps;
  for (std::size_t k = 1; k < slices.size(); ++k) {
    const double gap = slices[k].along - slices[k - 1].along;
    if (gap < 1e-3)
      throw InputError(where + ": files " + name(slices[k - 1]) + " and " + name(slices[k]) +
                       " lie at the same place (" + mm(slices[k].along) +
                       " along the slice normal); remove the duplicate");
    gaps.push_back(gap);
  }
  std::vector<double> sorted = gaps;
  std::nth_element(sorted.begin(), sorted.begin() + long(sorted.size() / 2), sorted.end());
  const double spacing = sorted[sorted.size() / 2];
  for (std::size_t k = 0; k < gaps.size(); ++k) {
    if (std::abs(gaps[k] - spacing) > 0.01 * spacing + 1e-3) {
      const long missing = std::lround(gaps[k] / spacing) - 1;
      throw InputError(
          where + ": files " + name(slices[k]) + " and " + name(slices[k + 1]) + " lie " + mm(gaps[k]) +
          " apart where the other slices are " + mm(spacing) + " apart" +
          (missing >= 1 ? " (" + std::to_string(missing) + " slice" + (missing > 1 ? "s" : "") + " missing?)"
                        : "") +
          (out.empty_files.empty()
               ? std::string()
               : "; the folder holds " + format_counted(out.empty_files.size(), "empty file") + " ('" +
                     out.empty_files.front() + "'" + (out.empty_files.size() > 1 ? ", ..." : "") +
                     "): an incomplete copy?") +
          "; a volume needs evenly spaced slices: export the whole series again");
    }
    // Each slice must lie straight along the normal from the first (no gantry tilt, no shift).
    const Vec3& p = slices[k + 1].position;
    const double d = slices[k + 1].along - first.along;
    const Vec3& p0 = slices.front().position;
    for (int a = 0; a < 3; ++a)
      if (std::abs(p[a] - p0[a] - d * normal[a]) > 0.01 * spacing + 1e-3)
        throw InputError(where + ": file " + name(slices[k + 1]) +
                         " is shifted sideways against the first slice (a gantry tilt): the volume is "
                         "sheared; resample it to an orthogonal grid first");
  }

  out.dims = {first.size[0], first.size[1], int(slices.size())};
  out.spacing = {first.pixel_spacing[0], first.pixel_spacing[1], spacing};
  out.first = slices.front().position;
  out.axes = {first.row, first.column, normal};
  out.series_uid = uid;
  out.series_number = s.tags.number;
  out.modality = s.tags.modality;
  out.description = s.tags.description;
  out.values.reserve(std::size_t(out.dims[0]) * out.dims[1] * out.dims[2]);
  for (Slice& sl : slices) {
    out.values.insert(out.values.end(), sl.values.begin(), sl.values.end());
    std::vector<float>().swap(sl.values);  // a 300-slice CT holds 300 MB of floats: not twice
  }
  return out;
}

std::vector<std::string> write_dicom_series(const std::string& folder, const VoxelVolume& volume,
                                            const DicomWriteOptions& options) {
  quiet_gdcm();
  const std::array<int, 3>& n = volume.dims;
  const Vec3 spacing = volume.spacing_xyz();
  if (!(options.slope != 0) || !std::isfinite(options.slope) || !std::isfinite(options.intercept))
    throw InputError("DICOM writer: the rescale slope must be a finite non-zero number");
  // The UIDs are made from what the series holds, so the same volume gives the same files.
  ContentHash content;
  content.add(volume.values.data(), volume.values.size() * sizeof(float));
  content.add(n.data(), sizeof(int) * 3);
  content.add(volume.origin.data(), sizeof(double) * 3);
  content.add(spacing.data(), sizeof(double) * 3);
  const std::string study_uid = content.uid("study");
  const std::string series_uid = content.uid("series");
  const std::string frame_uid = content.uid("frame");

  std::vector<std::string> names;
  const std::size_t per_slice = std::size_t(n[0]) * std::size_t(n[1]);
  std::vector<int16_t> stored(per_slice);
  for (int k = 0; k < n[2]; ++k) {
    for (std::size_t i = 0; i < per_slice; ++i) {
      const double s = std::round((volume.values[k * per_slice + i] - options.intercept) / options.slope);
      stored[i] = static_cast<int16_t>(std::clamp(s, -32768.0, 32767.0));
    }
    gdcm::ImageWriter writer;
    gdcm::Image& image = writer.GetImage();
    image.SetNumberOfDimensions(2);
    image.SetDimension(0, static_cast<unsigned int>(n[0]));
    image.SetDimension(1, static_cast<unsigned int>(n[1]));
    image.SetPixelFormat(gdcm::PixelFormat::INT16);
    image.SetPhotometricInterpretation(gdcm::PhotometricInterpretation::MONOCHROME2);
    image.SetSpacing(0, spacing[0]);
    image.SetSpacing(1, spacing[1]);
    image.SetOrigin(0, volume.origin[0]);
    image.SetOrigin(1, volume.origin[1]);
    image.SetOrigin(2, volume.origin[2] + k * spacing[2]);
    const double axial[6] = {1, 0, 0, 0, 1, 0};
    image.SetDirectionCosines(axial);
    image.SetSlope(options.slope);
    image.SetIntercept(options.intercept);
    gdcm::DataElement pixels(gdcm::Tag(0x7fe0, 0x0010));
    pixels.SetByteValue(reinterpret_cast<const char*>(stored.data()),
                        static_cast<uint32_t>(stored.size() * sizeof(int16_t)));
    image.SetDataElement(pixels);

    gdcm::DataSet& ds = writer.GetFile().GetDataSet();
    put_text(ds, 0x0008, 0x0016, gdcm::VR::UI, "1.2.840.10008.5.1.4.1.1.2");  // CT Image Storage
    put_text(ds, 0x0008, 0x0018, gdcm::VR::UI, content.uid("slice" + std::to_string(k)));
    // Left empty, or GDCM writes the time of writing into every file (the same volume, other bytes).
    put_text(ds, 0x0008, 0x0020, gdcm::VR::DA, "");  // study date and time
    put_text(ds, 0x0008, 0x0030, gdcm::VR::TM, "");
    put_text(ds, 0x0008, 0x0060, gdcm::VR::CS, "CT");
    put_text(ds, 0x0008, 0x103e, gdcm::VR::LO, "hexbite CT-like volume");
    put_text(ds, 0x0010, 0x0010, gdcm::VR::PN, options.patient_name);
    put_text(ds, 0x0020, 0x000d, gdcm::VR::UI, study_uid);
    put_text(ds, 0x0020, 0x000e, gdcm::VR::UI, series_uid);
    put_text(ds, 0x0020, 0x0052, gdcm::VR::UI, frame_uid);
    put_text(ds, 0x0020, 0x0011, gdcm::VR::IS, std::to_string(options.series_number));
    put_text(ds, 0x0020, 0x0013, gdcm::VR::IS, std::to_string(k + 1));
    put_text(ds, 0x0018, 0x0050, gdcm::VR::DS, std::to_string(spacing[2]));  // slice thickness

    char file[32];
    std::snprintf(file, sizeof file, "ct_%04d.dcm", k + 1);
    const std::string path = (fs::path(folder) / file).string();
    // Into memory first: GDCM's writer asserts (the process aborted, exit 134) when its file stream fails
    // on a full disk; the bytes are then written and checked here.
    std::ostringstream bytes;
    writer.SetStream(bytes);
    if (!writer.Write()) throw RunError("cannot write '" + path + "': GDCM could not encode the slice");
    const std::string encoded = bytes.str();
    std::ofstream out(path, std::ios::binary);
    out.write(encoded.data(), static_cast<std::streamsize>(encoded.size()));
    out.close();
    if (!out) throw RunError("cannot write '" + path + "': " + kWriteFailed + ": " + kWriteAdvice);
    names.push_back(file);
  }
  return names;
}

}  // namespace hexbite
