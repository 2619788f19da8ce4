// CT volumes as DICOM series: a folder of slice files, as scanners and PACS export them.
//
// Why: a surgeon's CT comes as DICOM, not as MetaImage or NIfTI; converting it first with another tool is a
// step where a mirrored or shifted volume goes unnoticed. DICOM's patient coordinates (LPS: +x toward the
// patient's left, +y posterior, +z superior, millimetres) are hexbite's mandible frame, so the positions of
// the slices place the bone without any further convention.
//
// Reading and writing the files is GDCM's (the DICOM library of ITK and 3D Slicer: every transfer syntax,
// compressed ones included, and the rescale to Hounsfield units); what is written here is which files form
// the volume and in which order, and the checks that tell a user what is wrong with a folder.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "mesher/mandible_generator.h"
#include "mesher/vec3.h"

namespace hexbite {

// A series as read, in its own index order: column index i fastest, then row j, then slice k in the order
// of the slices' positions along their normal.
struct DicomSeries {
  std::array<int, 3> dims{};
  std::array<double, 3> spacing{};  // along i, j, k in mm (Pixel Spacing's column and row spacing; slices)
  Vec3 first{};                     // Image Position (Patient) of the first slice: voxel (0, 0, 0), mm
  std::array<Vec3, 3> axes{};       // unit directions of i (the rows), j (the columns) and k (the normal)
  std::vector<float> values;        // rescaled: Hounsfield units for CT
  std::string series_uid, series_number, modality, description;
  int other_files = 0;  // files in the folder that are no DICOM images (a DICOMDIR, notes), left out
  std::vector<std::string> empty_files;  // those of them that are empty (0 bytes): names in the folder
};

// Reads an image series in `folder` (every file in it, whatever its name; sub-folders are not read): the
// only one, or the one that `series` names by its Series Instance UID, Series Number or Series Description.
// Throws InputError naming the folder (and the file) when it holds no DICOM image, more than one series and
// `series` is empty (each named by its number, description, slice count and UID), no series or more than
// one of that name, slices of different sizes, orientations or pixel spacings, slices at the same place or
// unevenly spaced (a missing slice), or pixels of more than one sample (colour).
DicomSeries read_dicom_series(const std::string& folder, const std::string& series = {});

// Whether `file` starts as a DICOM file does: a 128-byte preamble and "DICM" (Part 10). A slice of a series
// has it; a text file or a volume file given in its place does not.
bool has_dicom_preamble(const std::string& file);

struct DicomWriteOptions {
  double slope = 1.0;  // stored value = round((value - intercept) / slope), as signed 16-bit integers
  double intercept = 0.0;
  std::string patient_name = "hexbite^procedural mandible";
  int series_number = 1;
};

// Writes `volume` as a CT series into the existing folder `folder`, one file per slice along z, named
// ct_0001.dcm, ct_0002.dcm, ...; returns their names. Axial slices (orientation 1\0\0\0\1\0), positions
// and spacing from the volume; the UIDs are made from the volume's content (2.25.<decimal>), so the same
// volume gives the same bytes. Values outside what 16 bits hold with this slope and intercept are clipped.
std::vector<std::string> write_dicom_series(const std::string& folder, const VoxelVolume& volume,
                                            const DicomWriteOptions& options = {});

}  // namespace hexbite
