// CT volumes as DICOM series (mesher/dicom_series.h): written, read back, cross-checked with VTK's own
// DICOM reader, and every folder a scanner export can get wrong refused with the file named.
#include <gdcmImageChangeTransferSyntax.h>
#include <gdcmImageReader.h>
#include <gdcmImageWriter.h>
#include <gdcmReader.h>
#include <gdcmWriter.h>
#include <gtest/gtest.h>
#include <vtkDICOMImageReader.h>
#include <vtkImageData.h>
#include <vtkSmartPointer.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "common/error.h"
#include "mesher/ct_surface.h"
#include "mesher/dicom_series.h"
#include "mesher/surface_io.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

namespace fs = std::filesystem;

// A small anisotropic volume whose values the series stores exactly with slope 0.5 and intercept -1024: a
// mirrored, shifted or transposed read changes them.
VoxelVolume test_volume(int nx = 12, int ny = 9, int nz = 7) {
  VoxelVolume v;
  v.dims = {nx, ny, nz};
  v.origin = {-10.0, 5.5, 30.0};
  v.axis_spacing = {0.5, 0.75, 1.25};
  v.spacing = 0.5;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) v.values.push_back(float(-1024.0 + 0.5 * (i + 37 * j + 401 * k)));
  return v;
}

DicomWriteOptions rescaled() {
  DicomWriteOptions o;
  o.slope = 0.5;
  o.intercept = -1024;
  return o;
}

std::string written_series(const VoxelVolume& v = test_volume()) {
  const std::string dir = test::temp_dir() + "/series";
  fs::create_directories(dir);
  write_dicom_series(dir, v, rescaled());
  return dir;
}

void expect_same_volume(const VoxelVolume& back, const VoxelVolume& v) {
  EXPECT_EQ(back.dims, v.dims);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(back.origin[a], v.origin[a], 1e-6) << a;
    EXPECT_NEAR(back.spacing_xyz()[a], v.spacing_xyz()[a], 1e-6) << a;
  }
  EXPECT_TRUE(back.values == v.values);
}

std::string error_of(const std::string& folder) {
  try {
    read_volume(folder);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(DicomSeries, AVolumeWrittenAsASeriesReadsBackExactly) {
  const VoxelVolume v = test_volume();
  const std::string dir = test::temp_dir() + "/series";
  fs::create_directories(dir);
  const std::vector<std::string> names = write_dicom_series(dir, v, rescaled());
  ASSERT_EQ(names.size(), 7u);
  EXPECT_EQ(names.front(), "ct_0001.dcm");
  expect_same_volume(read_volume(dir), v);
  const DicomSeries s = read_dicom_series(dir);
  EXPECT_EQ(s.modality, "CT");
  EXPECT_EQ(s.series_uid.rfind("2.25.", 0), 0u) << s.series_uid;
  // The same volume gives the same bytes (the UIDs come from the content, no time of writing).
  const std::string again = test::temp_dir() + "/again";
  fs::create_directories(again);
  write_dicom_series(again, v, rescaled());
  for (const std::string& name : names)
    EXPECT_EQ(test::read_file(dir + "/" + name), test::read_file(again + "/" + name)) << name;
}

// VTK's DICOM reader, an independent parser, sees the same grid. It hands over the Pixel Spacing tag's two
// values in the file's order, which DICOM defines as the row spacing (between rows: along j, 0.75 mm) and
// then the column spacing (along i, 0.5 mm): a writer and a reader of ours that both swapped them would
// agree with each other, and a surgeon's scan with non-square pixels would come out stretched.
TEST(DicomSeries, VtksOwnDicomReaderSeesTheSameGrid) {
  const std::string dir = written_series();
  auto reader = vtkSmartPointer<vtkDICOMImageReader>::New();
  reader->SetDirectoryName(dir.c_str());
  reader->Update();
  int dims[3];
  reader->GetOutput()->GetDimensions(dims);
  EXPECT_EQ(dims[0], 12);
  EXPECT_EQ(dims[1], 9);
  EXPECT_EQ(dims[2], 7);
  const double* spacing = reader->GetPixelSpacing();
  EXPECT_NEAR(spacing[0], 0.75, 1e-6);  // the tag's first value: the row spacing
  EXPECT_NEAR(spacing[1], 0.5, 1e-6);
  EXPECT_NEAR(reader->GetRescaleSlope(), 0.5, 1e-9);
  EXPECT_NEAR(reader->GetRescaleOffset(), -1024, 1e-9);
}

// PACS exports are often compressed: the slices re-encoded as JPEG lossless, JPEG 2000 lossless and RLE
// (GDCM's codecs) read back to the same values.
TEST(DicomSeries, CompressedSlicesReadBackToTheSameValues) {
  const VoxelVolume v = test_volume();
  const std::string dir = written_series(v);
  const gdcm::TransferSyntax::TSType syntaxes[] = {gdcm::TransferSyntax::JPEGLosslessProcess14_1,
                                                   gdcm::TransferSyntax::JPEG2000Lossless,
                                                   gdcm::TransferSyntax::RLELossless};
  int k = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string file = entry.path().string();
    gdcm::ImageReader reader;
    reader.SetFileName(file.c_str());
    ASSERT_TRUE(reader.Read()) << file;
    gdcm::ImageChangeTransferSyntax change;
    const gdcm::TransferSyntax::TSType syntax = syntaxes[k++ % 3];
    change.SetTransferSyntax(syntax);
    change.SetInput(reader.GetImage());
    ASSERT_TRUE(change.Change()) << file;
    gdcm::ImageWriter writer;
    writer.SetFileName(file.c_str());
    writer.SetFile(reader.GetFile());
    writer.SetImage(change.GetOutput());
    ASSERT_TRUE(writer.Write()) << file;
    gdcm::ImageReader check;  // the file is compressed now, not a copy of the plain one
    check.SetFileName(file.c_str());
    ASSERT_TRUE(check.Read()) << file;
    EXPECT_EQ(check.GetFile().GetHeader().GetDataSetTransferSyntax(), gdcm::TransferSyntax(syntax)) << file;
  }
  expect_same_volume(read_volume(dir), v);
}

// Replaces a text tag of a DICOM file in place (DICOM pads text to an even length with a space).
void set_tag(const std::string& file, uint16_t group, uint16_t element, std::string value,
             gdcm::VR vr = gdcm::VR::DS) {
  gdcm::Reader reader;
  reader.SetFileName(file.c_str());
  ASSERT_TRUE(reader.Read()) << file;
  if (value.size() % 2 != 0) value += ' ';
  gdcm::DataElement de(gdcm::Tag(group, element));
  de.SetVR(vr);
  de.SetByteValue(value.data(), static_cast<uint32_t>(value.size()));
  reader.GetFile().GetDataSet().Replace(de);
  gdcm::Writer writer;
  writer.SetFileName(file.c_str());
  writer.SetFile(reader.GetFile());
  ASSERT_TRUE(writer.Write()) << file;
}

// A series stored with its rows running toward the patient's right and its columns anterior (orientation
// -1\0\0\0\-1\0, as some scanners write a prone scan), placed by its last pixel: the same positions hold
// the pixels mirrored in x and y. Reading it must mirror them back into place: a reader that ignored the
// orientation would swap the patient's left and right without a word.
TEST(DicomSeries, ReversedRowAndColumnDirectionsAreMirroredIntoPlace) {
  const VoxelVolume v = test_volume();
  const std::string dir = written_series(v);
  const Vec3 h = v.spacing_xyz();
  const double x_last = v.origin[0] + (v.dims[0] - 1) * h[0], y_last = v.origin[1] + (v.dims[1] - 1) * h[1];
  for (int k = 0; k < v.dims[2]; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "/ct_%04d.dcm", k + 1);
    char position[96];
    std::snprintf(position, sizeof position, "%.6f\\%.6f\\%.6f", x_last, y_last, v.origin[2] + k * h[2]);
    set_tag(dir + name, 0x0020, 0x0037, "-1\\0\\0\\0\\-1\\0");
    set_tag(dir + name, 0x0020, 0x0032, position);
  }
  const VoxelVolume back = read_volume(dir);
  ASSERT_EQ(back.dims, v.dims);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(back.origin[a], v.origin[a], 1e-5) << a;
  const auto at = [](const VoxelVolume& w, int i, int j, int k) {
    return w.values[(std::size_t(k) * w.dims[1] + j) * w.dims[0] + i];
  };
  int mismatches = 0;
  for (int k = 0; k < v.dims[2]; ++k)
    for (int j = 0; j < v.dims[1]; ++j)
      for (int i = 0; i < v.dims[0]; ++i)
        mismatches += at(back, i, j, k) != at(v, v.dims[0] - 1 - i, v.dims[1] - 1 - j, k);
  EXPECT_EQ(mismatches, 0);
}

// `surface from-ct` says which series it read, and warns of the files it left out and of a series that is
// no CT (whose threshold is then not in Hounsfield units).
TEST(DicomSeries, FromCtNamesTheSeriesAndWarnsOfWhatItLeftOut) {
  const std::string dir = written_series();
  test::write_file(dir + "/README.txt", "exported by the scanner\n");
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().extension() == ".dcm")
      set_tag(entry.path().string(), 0x0008, 0x0060, "MR", gdcm::VR::CS);
  const auto r = test::run_hexbite({"surface", "from-ct", dir, "--threshold", "0", "-o", dir + "/../mr.stl"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("DICOM series 1 'hexbite CT-like volume' (MR), 7 slices"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("left out 1 file of the folder that is no DICOM image"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the series' modality is MR, not CT: the threshold is in its own units"),
            std::string::npos)
      << r.err;
}

// Scanners name their files anyhow (by UID, by acquisition time): the order comes from the slices'
// positions, and files that are no DICOM image (a README, a DICOMDIR) are left out and counted.
TEST(DicomSeries, FileNamesDoNotOrderTheSlicesAndOtherFilesAreLeftOut) {
  const VoxelVolume v = test_volume();
  const std::string dir = written_series(v);
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  // Reverse the names: ct_0001.dcm now holds the last slice.
  for (std::size_t i = 0; i < names.size(); ++i) fs::rename(dir + "/" + names[i], dir + "/x" + names[i]);
  for (std::size_t i = 0; i < names.size(); ++i)
    fs::rename(dir + "/x" + names[i], dir + "/" + names[names.size() - 1 - i]);
  test::write_file(dir + "/README.txt", "exported by the scanner\n");
  expect_same_volume(read_volume(dir), v);
  EXPECT_EQ(read_dicom_series(dir).other_files, 1);
}

TEST(DicomSeries, AFolderWithoutASeriesIsRefused) {
  const std::string dir = test::temp_dir() + "/empty";
  fs::create_directories(dir);
  test::write_file(dir + "/notes.txt", "no images here\n");
  EXPECT_NE(error_of(dir).find("'" + dir + "' holds no DICOM image (1 file read)"), std::string::npos)
      << error_of(dir);
}

// A slice file given for its series (what a file dialog hands over) is told to give the folder.
TEST(DicomSeries, OneSliceFileIsToldToGiveItsFolder) {
  const std::string dir = written_series();
  const std::string e = error_of(dir + "/ct_0002.dcm");
  EXPECT_NE(
      e.find("is one DICOM file (a slice of a series); give the folder that holds the series: '" + dir + "'"),
      std::string::npos)
      << e;
}

TEST(DicomSeries, AMissingSliceIsNamedByTheFilesAroundTheGap) {
  const std::string dir = written_series();
  fs::remove(dir + "/ct_0004.dcm");
  const std::string e = error_of(dir);
  EXPECT_NE(
      e.find("files 'ct_0003.dcm' and 'ct_0005.dcm' lie 2.5 mm apart where the other slices are 1.25 mm "
             "apart (1 slice missing?)"),
      std::string::npos)
      << e;
}

// GDCM's writer asserted on a full disk (the process aborted, exit 134, the slices written so far left).
TEST(DicomSeries, AFailedSliceWriteIsAnError) {
  const std::string dir = test::temp_dir();
  std::string message;
  {
    const test::FileSizeLimit limit(100);
    message = test::message_of<RunError>([&] { write_dicom_series(dir, test_volume(), rescaled()); });
  }
  EXPECT_NE(message.find("cannot write '" + dir + "/ct_0001.dcm': the disk is full"), std::string::npos)
      << message;
}

// An empty slice file (a copy that stopped before the slice's first byte) was told only as a missing slice.
TEST(DicomSeries, AnEmptySliceFileIsNamedWithTheGap) {
  const std::string dir = written_series();
  test::write_file(dir + "/ct_0004.dcm", "");
  const std::string e = error_of(dir);
  EXPECT_NE(e.find("(1 slice missing?); the folder holds 1 empty file ('ct_0004.dcm'): an incomplete copy?"),
            std::string::npos)
      << e;
}

// An emptied last slice leaves no gap: the volume is one slice shorter, and the warning names the file.
TEST(DicomSeries, AnEmptyLastSliceIsNamedInTheWarning) {
  const std::string dir = written_series();
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  test::write_file(dir + "/" + names.back(), "");
  const auto r = test::run_hexbite({"surface", "from-ct", dir, "--threshold", "0", "-o", dir + "/../ct.stl"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("left out 1 file of the folder that is no DICOM image (1 of them empty, '" +
                       names.back() + "' first: a slice cut off by an incomplete copy?"),
            std::string::npos)
      << r.err;
}

// A slice cut off inside its header (after 160 to 300 bytes): GDCM asserted and the process aborted (exit
// 134, a backtrace from `run`). Now refused, naming the file.
TEST(DicomSeries, ASliceCutOffInItsHeaderIsNamed) {
  const std::string dir = written_series();
  const std::string file = dir + "/ct_0004.dcm";
  const std::string bytes = test::read_file(file);
  for (std::size_t keep : {160, 200, 244}) {
    test::write_file(file, bytes.substr(0, keep));
    const std::string e = error_of(dir);
    EXPECT_NE(e.find("file 'ct_0004.dcm' is cut off in its header (" + std::to_string(keep) + " bytes"),
              std::string::npos)
        << e;
  }
}

// A slice file cut off in its pixel data (an interrupted copy): GDCM reads what is there and fills the rest,
// which gave a bone with a hole in it and exit 0. Now refused, naming the file.
TEST(DicomSeries, ASliceCutOffInItsPixelDataIsNamed) {
  const std::string dir = written_series();
  const std::string file = dir + "/ct_0004.dcm";
  const std::string bytes = test::read_file(file);
  test::write_file(file, bytes.substr(0, bytes.size() - 50));
  const std::string e = error_of(dir);
  EXPECT_NE(e.find("file 'ct_0004.dcm' is cut off in its pixel data"), std::string::npos) << e;
}

TEST(DicomSeries, ADuplicateSliceIsNamed) {
  const std::string dir = written_series();
  fs::copy_file(dir + "/ct_0003.dcm", dir + "/copy.dcm");
  const std::string e = error_of(dir);
  EXPECT_NE(e.find("lie at the same place"), std::string::npos) << e;
  EXPECT_NE(e.find("'copy.dcm'"), std::string::npos) << e;
}

// Two series in one folder (a scout and the bone kernel, say): refused with both named, not mixed; one of
// them is chosen by its Series Number or UID (their descriptions are the same here, so that names both).
TEST(DicomSeries, TwoSeriesInOneFolderAreNamedNotMixedAndOneIsChosen) {
  const VoxelVolume first = test_volume();
  const std::string dir = written_series(first);
  const std::string other = test::temp_dir() + "/other";
  fs::create_directories(other);
  const VoxelVolume second = test_volume(12, 9, 5);
  DicomWriteOptions numbered = rescaled();
  numbered.series_number = 2;
  write_dicom_series(other, second, numbered);
  for (const auto& e : fs::directory_iterator(other))
    fs::copy_file(e.path(), dir + "/b_" + e.path().filename().string());
  const std::string e = error_of(dir);
  EXPECT_NE(e.find("holds 2 DICOM series (number "), std::string::npos) << e;
  EXPECT_NE(e.find("number 1, 'hexbite CT-like volume', 7 slices, UID 2.25."), std::string::npos) << e;
  EXPECT_NE(e.find("number 2, 'hexbite CT-like volume', 5 slices, UID 2.25."), std::string::npos) << e;
  EXPECT_NE(e.find("choose one by its number, description or UID"), std::string::npos) << e;

  expect_same_volume(read_volume(dir, nullptr, "1"), first);
  const DicomSeries by_number = read_dicom_series(dir, "2");
  EXPECT_EQ(by_number.dims[2], 5);
  expect_same_volume(read_volume(dir, nullptr, by_number.series_uid), second);
  std::string named;
  try {
    read_dicom_series(dir, "hexbite CT-like volume");
  } catch (const InputError& x) {
    named = x.what();
  }
  EXPECT_NE(named.find("holds 2 DICOM series that 'hexbite CT-like volume' names"), std::string::npos)
      << named;
  std::string none;
  try {
    read_dicom_series(dir, "7");
  } catch (const InputError& x) {
    none = x.what();
  }
  EXPECT_NE(none.find("holds no DICOM series numbered, described or identified as '7'; its series: number 1"),
            std::string::npos)
      << none;
  // The command line and a volume file.
  const auto r = test::run_hexbite(
      {"-q", "surface", "from-ct", dir, "--series", "2", "--threshold", "-500", "-o", other + "/../two.stl"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THROW(read_volume(other + "/ct_0001.dcm", nullptr, "2"), InputError);
}

TEST(DicomSeries, ASingleSliceIsNoVolume) {
  const std::string dir = test::temp_dir() + "/one";
  fs::create_directories(dir);
  write_dicom_series(dir, test_volume(12, 9, 1), rescaled());
  EXPECT_NE(error_of(dir).find("has one slice; a volume needs at least two"), std::string::npos)
      << error_of(dir);
}

// The command line: `generate --dicom` writes a series that `surface from-ct` reads as it reads the
// MetaImage of the same volume (the series rounds the values to whole Hounsfield units), and a second
// generate into the folder leaves one series.
TEST(DicomSeries, GenerateWritesASeriesThatSurfaceFromCtReads) {
  const std::string dir = test::temp_dir();
  const auto gen = test::run_hexbite({"-q", "generate", "mandible", "-o", dir + "/jaw.stl", "--ct",
                                      dir + "/jaw.mha", "--dicom", dir + "/jaw_ct"});
  ASSERT_EQ(gen.exit_code, 0) << gen.err;
  EXPECT_TRUE(fs::exists(dir + "/jaw_ct/ct_0001.dcm"));
  for (const char* input : {"jaw.mha", "jaw_ct"}) {
    const auto r = test::run_hexbite({"-q", "surface", "from-ct", dir + "/" + input, "--threshold", "620",
                                      "-o", dir + "/" + input + ".stl"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const TriSurface from_mha = read_surface(dir + "/jaw.mha.stl");
  const TriSurface from_dicom = read_surface(dir + "/jaw_ct.stl");
  auto box = [](const TriSurface& s) {
    std::array<double, 6> b{1e9, 1e9, 1e9, -1e9, -1e9, -1e9};
    for (const Vec3& p : s.vertices)
      for (int a = 0; a < 3; ++a) b[a] = std::min(b[a], p[a]), b[a + 3] = std::max(b[a + 3], p[a]);
    return b;
  };
  const auto b0 = box(from_mha), b1 = box(from_dicom);
  for (int a = 0; a < 6; ++a) EXPECT_NEAR(b1[a], b0[a], 0.01) << a;  // not mirrored, not shifted
  EXPECT_NEAR(double(from_dicom.triangles.size()), double(from_mha.triangles.size()),
              0.01 * double(from_mha.triangles.size()));

  // A second, smaller volume (coarser voxels) into the same folder: its slices replace the first run's and
  // the first run's surplus slices are removed, so the folder holds one series.
  const auto coarse = test::run_hexbite(
      {"-q", "generate", "mandible", "-o", dir + "/jaw2.stl", "--voxel", "1.5", "--dicom", dir + "/jaw_ct"});
  ASSERT_EQ(coarse.exit_code, 0) << coarse.err;
  const DicomSeries s = read_dicom_series(dir + "/jaw_ct");
  EXPECT_NEAR(s.spacing[2], 1.5, 1e-9);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir + "/jaw_ct"), fs::directory_iterator{}), s.dims[2]);
}

// Two outputs of one path failed after the work, when the second was moved in ("a folder of that name is in
// the way", exit 1); they are a usage error before it, naming both options. Outputs inside the --dicom
// folder are fine.
TEST(DicomSeries, GenerateRefusesTwoOutputsOfOnePath) {
  const std::string dir = test::temp_dir();
  const std::string jaw = dir + "/jaw.stl";
  struct Case {
    std::vector<std::string> options;
    std::string fragment;
  };
  const std::vector<Case> cases = {
      {{"--dicom", jaw}, "-o '" + jaw + "' and --dicom '" + jaw + "' are the same path"},
      {{"--dicom", dir + "/./jaw.stl/"}, "are the same path; give each output its own name"},
      {{"--ct", dir + "/ct.mha", "--dicom", dir + "/ct.mha"}, "--ct '" + dir + "/ct.mha' and --dicom"},
      {{"--landmarks", dir + "/l.yaml", "--dicom", dir + "/l.yaml"}, "--landmarks '" + dir + "/l.yaml' and"},
      {{"--dicom", dir + "/jaw.landmarks.yaml"}, "the landmark file (its default name, from -o)"},
      {{"--dicom", jaw + "/ct"}, "the second lies inside the first, which is a file"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = {"generate", "mandible", "-o", jaw};
    args.insert(args.end(), c.options.begin(), c.options.end());
    const auto r = test::run_hexbite(args);
    EXPECT_EQ(r.exit_code, 2) << c.options.back() << "\n" << r.err;
    EXPECT_NE(r.err.find(c.fragment), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_empty(dir));
  }
}

// A folder in the way of a slice's name failed the DICOM folder's commit after the surface, landmarks and
// CT had been moved in (the earlier jaw.stl replaced); every folder is now checked before the first move.
// And a file of a slice's name that is no DICOM file (ct_9999.dcm of text) is the user's: an earlier series'
// retirement removed it.
TEST(DicomSeries, GenerateLeavesEarlierFilesWhenTheSeriesCannotBeMovedInAndKeepsTheUsersFiles) {
  const std::string dir = test::temp_dir();
  fs::create_directories(dir + "/ct/ct_0005.dcm");
  test::write_file(dir + "/jaw.stl", "OLD\n");
  const std::map<std::string, std::string> before = test::files_under(dir);
  const std::vector<std::string> generate = {
      "-q",      "generate", "mandible", "-o",       dir + "/jaw.stl", "--ct", dir + "/jaw.mha",
      "--voxel", "1.5",      "--dicom",  dir + "/ct"};
  auto r = test::run_hexbite(generate);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("cannot write '" + dir + "/ct/ct_0005.dcm': a folder of that name is in the way"),
            std::string::npos)
      << r.err;
  test::expect_same_files(before, test::files_under(dir));

  fs::remove(dir + "/ct/ct_0005.dcm");
  test::write_file(dir + "/ct/ct_9999.dcm", "my notes\n");
  r = test::run_hexbite(generate);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  fs::copy_file(dir + "/ct/ct_0001.dcm", dir + "/ct/ct_9998.dcm");  // a slice of a longer, earlier series
  r = test::run_hexbite(generate);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(test::read_file(dir + "/ct/ct_9999.dcm"), "my notes\n");
  EXPECT_FALSE(fs::exists(dir + "/ct/ct_9998.dcm"));
}

}  // namespace
}  // namespace hexbite
