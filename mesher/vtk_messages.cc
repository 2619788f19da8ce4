#include "mesher/vtk_messages.h"

#include <vtkDataArraySelection.h>
#include <vtkLZ4DataCompressor.h>
#include <vtkLZMADataCompressor.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkSmartPointer.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>
#include <vtkXMLReader.h>
#include <vtkZLibDataCompressor.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

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
// array without a name (in `unnamed`, as "CellData of piece 0"), if any.
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
          if (const char* array_name = arrays->GetNestedElement(k)->GetAttribute("Name");
              array_name == nullptr || *array_name == '\0')
            *unnamed = std::string("<") + data + "> of piece " + std::to_string(*piece);
    ++*piece;
  }
  return found;
}

// Throws when a <DataArray> below e announces fewer than 1 or more than 1,000 components: VTK's reader
// resized its arrays by the negative count and failed with the C++ library's "vector::_M_default_append".
void check_component_counts(vtkXMLDataElement* e, const std::string& file) {
  for (int i = 0; i < e->GetNumberOfNestedElements(); ++i) {
    vtkXMLDataElement* child = e->GetNestedElement(i);
    if (child->GetName() != nullptr && std::strcmp(child->GetName(), "DataArray") == 0)
      if (const char* value = child->GetAttribute("NumberOfComponents")) {
        errno = 0;
        const long long n = std::strtoll(value, nullptr, 10);
        if (n < 1 || n > 1000 || errno == ERANGE) {
          const char* name = child->GetAttribute("Name");
          throw InputError("cannot read '" + file + "': its data array '" + (name ? name : "(unnamed)") +
                           "' announces NumberOfComponents=\"" + value +
                           "\", not from 1 to 1000; the file is damaged");
        }
      }
    check_component_counts(child, file);
  }
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
      if (n < 0)  // a negative count crashed VTK's reader of compressed data (exit 139)
        throw InputError(
            "cannot read '" + file + "': its <Piece> announces " + count + "=\"" + value +
            "\", a negative count; the file is damaged (check the counts in its <Piece> element)");
    }
    check_component_counts(child, file);
  }
}

// A data array of a piece: its element, where it is stored (format "ascii", "binary" or "appended"), its
// offset in the appended section, its name ("points" for the coordinates), the section it sits in
// (Points, PointData, CellData, Cells), and the values and bytes its data must have uncompressed (-1 when
// the piece's counts do not say, as for a cell connectivity or a text array).
struct DataArrayEntry {
  vtkXMLDataElement* element = nullptr;
  std::string format;
  long long offset = -1;
  std::string name;
  std::string section;
  long long values = -1;
  long long bytes = -1;
};

long long attribute_count(vtkXMLDataElement* e, const char* key) {
  const char* value = e != nullptr ? e->GetAttribute(key) : nullptr;
  return value != nullptr ? std::strtoll(value, nullptr, 10) : -1;
}

long long type_size(const char* type) {
  if (type == nullptr) return -1;
  const std::string t(type);
  if (t == "Float64" || t == "Int64" || t == "UInt64") return 8;
  if (t == "Float32" || t == "Int32" || t == "UInt32") return 4;
  if (t == "Int16" || t == "UInt16") return 2;
  if (t == "Int8" || t == "UInt8") return 1;
  return -1;
}

// The data arrays below e; `piece` and `section` are e's <Piece> and the element the arrays sit in (Points,
// PointData, CellData, Cells).
void data_arrays(vtkXMLDataElement* e, vtkXMLDataElement* piece, const std::string& section,
                 std::vector<DataArrayEntry>& out) {
  for (int i = 0; i < e->GetNumberOfNestedElements(); ++i) {
    vtkXMLDataElement* child = e->GetNestedElement(i);
    const std::string name = child->GetName() != nullptr ? child->GetName() : "";
    if (name == "DataArray") {
      DataArrayEntry a;
      a.element = child;
      a.format = child->GetAttribute("format") ? child->GetAttribute("format") : "";
      a.section = section;
      errno = 0;
      a.offset = attribute_count(child, "offset");
      if (errno == ERANGE) a.offset = -1;
      a.name = child->GetAttribute("Name") ? child->GetAttribute("Name")
               : section == "Points"       ? "points"
                                           : "(unnamed)";
      const long long points = attribute_count(piece, "NumberOfPoints"),
                      cells = attribute_count(piece, "NumberOfCells");
      long long tuples = -1;
      if (section == "Points" || section == "PointData") tuples = points;
      if (section == "CellData" || (section == "Cells" && a.name != "connectivity")) tuples = cells;
      const long long components = std::max(1LL, attribute_count(child, "NumberOfComponents"));
      const long long size = type_size(child->GetAttribute("type"));
      if (tuples >= 0 && size > 0) {
        a.values = tuples * components;
        a.bytes = a.values * size;
      }
      out.push_back(a);
      continue;
    }
    data_arrays(child, name == "Piece" ? child : piece,
                name == "Piece" ? ""
                : name.empty()  ? section
                                : name,
                out);
  }
}

InputError damaged_array(const std::string& file, const std::string& name, const std::string& what) {
  return InputError("cannot read '" + file + "': the data of its array '" + name + "' " + what +
                    "; the file is damaged (an offset or a size in it is wrong): export it again");
}

// Throws when a data array's block in the raw appended section does not lie within the file: VTK 9.1 reads a
// compressed array's block header at the array's offset and follows its sizes unchecked, so a wrong offset
// (one damaged digit) ended in a segmentation fault. Each block is a header (uncompressed: its byte count;
// compressed: the number of blocks, their size, the last one's size and each block's compressed size, in
// the file's header_type) followed by the bytes it announces. Hand-written: VTK has no check of its own.
void check_appended_blocks(vtkXMLDataElement* root, const std::string& file) {
  std::vector<DataArrayEntry> arrays;
  data_arrays(root, nullptr, "", arrays);
  arrays.erase(std::remove_if(arrays.begin(), arrays.end(),
                              [](const DataArrayEntry& a) { return a.format != "appended"; }),
               arrays.end());
  if (arrays.empty()) return;
  std::ifstream in(file, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t tag = bytes.find("<AppendedData");
  if (tag == std::string::npos) return;  // VTK says so
  const std::size_t tag_end = bytes.find('>', tag);
  if (tag_end == std::string::npos || bytes.substr(tag, tag_end - tag).find("\"raw\"") == std::string::npos)
    return;  // base64: VTK decodes and checks it
  const std::size_t start = bytes.find('_', tag_end);
  if (start == std::string::npos) return;
  const std::size_t data = start + 1, end = bytes.size();
  const char* header_type = root->GetAttribute("header_type");
  const std::size_t word = header_type != nullptr && std::strcmp(header_type, "UInt64") == 0 ? 8 : 4;
  const bool compressed = root->GetAttribute("compressor") != nullptr;
  const auto read_word = [&](std::size_t at) {  // little-endian, as hexbite's and most writers' files are
    unsigned long long v = 0;
    for (std::size_t k = 0; k < word; ++k)
      v |= static_cast<unsigned long long>(static_cast<unsigned char>(bytes[at + k])) << (8 * k);
    return v;
  };
  const char* byte_order = root->GetAttribute("byte_order");
  if (byte_order != nullptr && std::strcmp(byte_order, "LittleEndian") != 0) return;
  for (const DataArrayEntry& a : arrays) {
    const long long offset = a.offset, expected = a.bytes;
    const auto damaged = [&](const std::string& what) { return damaged_array(file, a.name, what); };
    if (offset < 0 || data + static_cast<unsigned long long>(offset) + word > end)
      throw damaged("would start at offset " + std::to_string(offset) + ", beyond the appended data's " +
                    std::to_string(end - data) + " bytes");
    std::size_t at = data + static_cast<std::size_t>(offset);
    unsigned long long payload = 0, size = 0;  // bytes in the file, and uncompressed
    if (!compressed) {
      payload = size = read_word(at);
      at += word;
    } else {
      if (at + 3 * word > end) throw damaged("has its block header cut off");
      const unsigned long long blocks = read_word(at);
      if (blocks > (end - at) / word)
        throw damaged("announces " + std::to_string(blocks) + " blocks, more than the file holds");
      if (at + (3 + blocks) * word > end) throw damaged("has its block header cut off");
      for (unsigned long long b = 0; b < blocks; ++b) payload += read_word(at + (3 + b) * word);
      const unsigned long long block = read_word(at + word), last = read_word(at + 2 * word);
      size = blocks == 0 ? 0 : (blocks - 1) * block + (last != 0 ? last : block);
      at += (3 + blocks) * word;
    }
    if (expected >= 0 && size != static_cast<unsigned long long>(expected))
      throw damaged("holds " + std::to_string(size) + " bytes where its piece's counts give " +
                    std::to_string(expected));
    if (payload > end - at)
      throw damaged("announces " + std::to_string(payload) + " bytes where " + std::to_string(end - at) +
                    " remain in the file");
  }
}

// Throws when an array stored in the file's XML (format "ascii" or base64 "binary") or in a base64 appended
// section holds more or fewer values than its piece's counts give: VTK 9.1 reads as many as the counts say
// and ignores the rest, so a file whose NumberOfCells was 1 too small lost its last hexes without a word.
// (A raw appended section is checked by check_appended_blocks.) The data is read in chunks, each one
// starting a word before the previous one ended, so that no read starts at the data's end: VTK's reader of
// compressed data then looks up a block beyond its table.
void check_array_lengths(vtkXMLDataElement* reader_root, const std::string& file) {
  std::vector<DataArrayEntry> arrays;
  data_arrays(reader_root, nullptr, "", arrays);
  vtkXMLDataElement* appended = reader_root->LookupElementWithName("AppendedData");
  const char* encoding = appended != nullptr ? appended->GetAttribute("encoding") : nullptr;
  const bool appended_base64 =
      appended != nullptr && (encoding == nullptr || std::strcmp(encoding, "raw") != 0);
  const auto checked = [&](const DataArrayEntry& a) {
    return a.format == "ascii" || a.format == "binary" || (a.format == "appended" && appended_base64);
  };
  if (std::none_of(arrays.begin(), arrays.end(), checked)) return;  // hexbite's own files: raw appended
  // A parser of its own: the reader's has closed its file after reading the XML (a read through it threw
  // "basic_ios::clear"). It finds the inline and appended data as the reader does; the compressor is set
  // as the reader sets it, from the file's compressor attribute.
  std::ifstream in(file, std::ios::binary);
  vtkNew<vtkXMLDataParser> parser;
  parser->SetStream(&in);
  if (parser->Parse() == 0 || parser->GetRootElement() == nullptr) return;  // the reader says what is wrong
  vtkXMLDataElement* root = parser->GetRootElement();
  if (const char* compressor = root->GetAttribute("compressor")) {
    vtkSmartPointer<vtkDataCompressor> c;
    if (std::strcmp(compressor, "vtkZLibDataCompressor") == 0)
      c = vtkSmartPointer<vtkZLibDataCompressor>::New();
    if (std::strcmp(compressor, "vtkLZ4DataCompressor") == 0)
      c = vtkSmartPointer<vtkLZ4DataCompressor>::New();
    if (std::strcmp(compressor, "vtkLZMADataCompressor") == 0)
      c = vtkSmartPointer<vtkLZMADataCompressor>::New();
    if (c == nullptr) return;  // the reader names an unknown compressor
    parser->SetCompressor(c);
  }
  arrays.clear();
  data_arrays(root, nullptr, "", arrays);
  constexpr unsigned long long kChunk = 1 << 20;
  std::vector<double> buffer;  // kChunk words of up to 8 bytes
  for (const DataArrayEntry& a : arrays) {
    if (!checked(a)) continue;
    const bool in_xml = a.format == "ascii" || a.format == "binary";
    // VTK finds an array's data after the first '>' of its element, even one inside the Name.
    if (in_xml && a.name.find('>') != std::string::npos)
      throw InputError("cannot read '" + file + "': its " +
                       (a.section == "CellData"    ? "cell array '"
                        : a.section == "PointData" ? "point array '"
                                                   : "array '") +
                       a.name + "' is stored in the XML (format=\"" + a.format +
                       "\") and its name holds a '>', which VTK's reader takes for the end of the element; "
                       "rename the array where the file was made (or save the file with appended data)");
    int word_type = 0;
    if (a.values < 0 || a.element->GetWordTypeAttribute("type", word_type) == 0) continue;
    if (buffer.empty()) buffer.resize(kChunk);
    const unsigned long long expected = static_cast<unsigned long long>(a.values);
    unsigned long long count = 0;
    for (;;) {
      const unsigned long long start = count == 0 ? 0 : count - 1;
      const std::size_t want = static_cast<std::size_t>(std::min(kChunk, expected + 1 - start));
      const std::size_t got =
          in_xml
              ? parser->ReadInlineData(a.element, a.format == "ascii", buffer.data(), start, want, word_type)
              : parser->ReadAppendedData(a.offset, buffer.data(), start, want, word_type);
      count = start + got;
      if (got < want || count > expected) break;
    }
    if (count != expected)
      throw damaged_array(
          file, a.name,
          count > expected
              ? "holds more than the " + std::to_string(expected) + " values its piece's counts give"
              : "holds " + std::to_string(count) + " values where its piece's counts give " +
                    std::to_string(expected));
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
      throw InputError(
          "cannot read '" + file + "': a data array in its " + unnamed +
          " has no name (its Name attribute is missing or empty); the file is damaged, or its writer "
          "left the name out");
    if (root != nullptr) {
      check_piece_counts(root, file);
      // A file read from a string (with_point_data above) has its data in that string, not in the file;
      // its offsets are the file's own, so the file's bytes are checked all the same.
      check_appended_blocks(root, file);
      check_array_lengths(root, file);
      disable_string_arrays(root, reader);
    }
    reader->Update();
  } catch (const std::length_error&) {
    // Sizes read from damaged data (bytes inserted into an appended section) that a vector cannot take:
    // "vector::_M_fill_insert", exit 1, and no file named.
    throw InputError(
        "cannot read '" + file +
        "': its data sections announce sizes that cannot be; the file is damaged (export it again)");
  } catch (const std::bad_alloc&) {
    // VTK allocates what the header announces before it reads the data.
    throw RunError("cannot read '" + file +
                   "': the points and cells it announces do not fit in memory; unless the data is that big, "
                   "the file is damaged (check the counts in its <Piece> element)");
  }
}

}  // namespace hexbite
