#include "mesher/vtk_messages.h"

#include <vtkDataArraySelection.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkSmartPointer.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>
#include <vtkXMLReader.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <new>

#include "common/error.h"

namespace hexbite {

namespace {

// Disables, in the reader's selections, the string arrays of every <PointData> and <CellData> below e.
void disable_string_arrays(vtkXMLDataElement* e, vtkXMLReader* reader) {
  for (int i = 0; i < e->GetNumberOfNestedElements(); ++i) {
    vtkXMLDataElement* child = e->GetNestedElement(i);
    const char* name = child->GetName();
    vtkDataArraySelection* selection =
        name == nullptr                       ? nullptr
        : std::strcmp(name, "PointData") == 0 ? reader->GetPointDataArraySelection()
        : std::strcmp(name, "CellData") == 0  ? reader->GetCellDataArraySelection()
                                              : nullptr;
    if (selection == nullptr) {
      disable_string_arrays(child, reader);
      continue;
    }
    for (int k = 0; k < child->GetNumberOfNestedElements(); ++k) {
      vtkXMLDataElement* array = child->GetNestedElement(k);
      const char* type = array->GetAttribute("type");
      const char* array_name = array->GetAttribute("Name");
      if (type != nullptr && array_name != nullptr && std::strcmp(type, "String") == 0)
        selection->DisableArray(array_name);
    }
  }
}

// Whether a <Piece> below e has a <CellData> but no <PointData> element, and the name of its first data
// array without a Name attribute (in `unnamed`, as "CellData of piece 0"), if any.
bool cell_data_without_point_data(vtkXMLDataElement* e, std::string* unnamed, int* piece) {
  bool found = false;
  for (int i = 0; i < e->GetNumberOfNestedElements(); ++i) {
    vtkXMLDataElement* child = e->GetNestedElement(i);
    const char* name = child->GetName();
    if (name == nullptr) continue;
    if (std::strcmp(name, "Piece") != 0) {
      found = cell_data_without_point_data(child, unnamed, piece) || found;
      continue;
    }
    const bool cells = child->FindNestedElementWithName("CellData") != nullptr;
    found = (cells && child->FindNestedElementWithName("PointData") == nullptr) || found;
    for (const char* data : {"PointData", "CellData"})
      if (vtkXMLDataElement* arrays = child->FindNestedElementWithName(data))
        for (int k = 0; k < arrays->GetNumberOfNestedElements() && unnamed->empty(); ++k)
          if (arrays->GetNestedElement(k)->GetAttribute("Name") == nullptr)
            *unnamed = std::string("<") + data + "> of piece " + std::to_string(*piece);
    ++*piece;
  }
  return found;
}

// Throws when a <Piece> below e announces more points or cells than hexbite reads (2^31 - 1 of each): VTK
// allocates what a piece announces before it reads the data, so a damaged count (10^15 points) ended in
// std::bad_alloc and a "does not fit in memory" failure instead of naming the damage.
void check_piece_counts(vtkXMLDataElement* e, const std::string& file) {
  for (int i = 0; i < e->GetNumberOfNestedElements(); ++i) {
    vtkXMLDataElement* child = e->GetNestedElement(i);
    const char* name = child->GetName();
    if (name == nullptr) continue;
    if (std::strcmp(name, "Piece") != 0) {
      check_piece_counts(child, file);
      continue;
    }
    for (const char* count : {"NumberOfPoints", "NumberOfCells", "NumberOfVerts", "NumberOfLines",
                              "NumberOfStrips", "NumberOfPolys"}) {
      const char* value = child->GetAttribute(count);
      if (value == nullptr) continue;
      errno = 0;
      const long long n = std::strtoll(value, nullptr, 10);
      if (n > std::numeric_limits<int>::max() || errno == ERANGE)
        throw InputError("cannot read '" + file + "': its <Piece> announces " + count + "=\"" + value +
                         "\", more than the 2^31 - 1 that hexbite reads; the file is damaged (check the "
                         "counts in its <Piece> element) or too large for hexbite");
    }
  }
}

// The file's text with an empty <PointData> before each <CellData> of its XML part (offsets into an
// appended data section count from that section's start, so they stay right).
std::string with_point_data(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t appended = text.find("<AppendedData");
  for (std::size_t at = text.find("<CellData"); at != std::string::npos && at < appended;
       at = text.find("<CellData", at + 30)) {
    text.insert(at, "<PointData></PointData>");
  }
  return text;
}

// VTK's text is "ERROR: In file.cxx, line N\nvtkClass (0x...): explanation\n\n"; keeps the explanation.
void append_explanation(std::string& list, const char* text) {
  if (text == nullptr) return;
  std::string t(text);
  if (t.rfind("ERROR: In ", 0) == 0 || t.rfind("Warning: In ", 0) == 0)
    t = t.substr(std::min(t.size(), t.find('\n') + 1));
  if (const std::size_t object = t.find("): "); object != std::string::npos) t = t.substr(object + 3);
  t = t.substr(0, t.find('\n'));
  // Follow-ups of an error already captured: the pipeline's failed request, and the piece request of an
  // Update() after a failed UpdateInformation() (update_xml_reader()).
  if (t.empty() || t.find("returned failure for request") != std::string::npos ||
      t.find("No update piece number has been set") != std::string::npos)
    return;
  if (!list.empty()) list += "; ";
  list += t;
}

class CapturingOutputWindow : public vtkOutputWindow {
 public:
  static CapturingOutputWindow* New();
  vtkTypeMacro(CapturingOutputWindow, vtkOutputWindow);
  void DisplayText(const char*) override {}
  void DisplayErrorText(const char* text) override { append_explanation(errors, text); }
  void DisplayWarningText(const char*) override {}
  void DisplayGenericWarningText(const char*) override {}
  void DisplayDebugText(const char*) override {}
  std::string errors;
};
vtkStandardNewMacro(CapturingOutputWindow);

}  // namespace

struct VtkMessageCapture::Impl {
  vtkSmartPointer<vtkOutputWindow> previous = vtkOutputWindow::GetInstance();
  vtkLogger::Verbosity previous_verbosity = vtkLogger::GetCurrentVerbosityCutoff();
  vtkNew<CapturingOutputWindow> capture;
};

VtkMessageCapture::VtkMessageCapture() : impl_(std::make_unique<Impl>()) {
  vtkOutputWindow::SetInstance(impl_->capture);
  vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
}

// The logger has no getter for the stderr level alone, so the overall cutoff (the stderr level unless a
// log file was opened) is what gets restored.
VtkMessageCapture::~VtkMessageCapture() {
  vtkLogger::SetStderrVerbosity(impl_->previous_verbosity);
  vtkOutputWindow::SetInstance(impl_->previous);
}

const std::string& VtkMessageCapture::errors() const {
  return impl_->capture->errors;
}
std::string VtkMessageCapture::reason() const {
  return errors().empty() ? std::string() : " (VTK: " + errors() + ")";
}

void update_xml_reader(vtkXMLReader* reader, const std::string& file) {
  try {
    reader->UpdateInformation();
    vtkXMLDataParser* parser = reader->GetXMLParser();
    vtkXMLDataElement* root = parser != nullptr ? parser->GetRootElement() : nullptr;
    std::string unnamed;
    int pieces = 0;
    // VTK 9.1 dereferences the missing <PointData> element when a cell data array of a piece without one
    // is too short (a segmentation fault in vtkXMLDataReader::ReadPieceData): such a file is read with an
    // empty <PointData> added, and the short array is then reported like any other.
    if (root != nullptr && cell_data_without_point_data(root, &unnamed, &pieces) && reader->GetFileName()) {
      reader->ReadFromInputStringOn();
      reader->SetInputString(with_point_data(file));
      reader->UpdateInformation();
      parser = reader->GetXMLParser();
      root = parser != nullptr ? parser->GetRootElement() : nullptr;
    }
    // VTK reads a file with an unnamed array as if it held no cells at all.
    if (!unnamed.empty())
      throw InputError("cannot read '" + file + "': a data array in its " + unnamed +
                       " has no Name attribute; the file is damaged, or its writer left the name out");
    if (root != nullptr) {
      check_piece_counts(root, file);
      disable_string_arrays(root, reader);
    }
    reader->Update();
  } catch (const std::bad_alloc&) {
    // VTK allocates what the header announces before it reads the data.
    throw RunError("cannot read '" + file +
                   "': the points and cells it announces do not fit in memory; unless the data is that big, "
                   "the file is damaged (check the counts in its <Piece> element)");
  }
}

}  // namespace hexbite
