#pragma once
// What VTK's readers and writers print, captured so that it reaches the user inside one InputError or
// RunError instead of as VTK's own multi-line, coloured log on the terminal; and a guard against a crash of
// VTK's XML readers on damaged files.

#include <memory>
#include <string>

class vtkXMLReader;

namespace hexbite {

// reader->Update() on the file set with SetFileName(), guarded against two failures of VTK 9.1's XML readers
// on damaged files: a string array with fewer values than its element announces crashes them (segmentation
// fault; no command uses string arrays, so the point and cell ones are not read at all), and a point or cell
// count beyond memory throws std::bad_alloc (then RunError naming `file`). Other errors are left for the
// caller to check (VtkMessageCapture, GetErrorCode()).
void update_xml_reader(vtkXMLReader* reader, const std::string& file);

// For its lifetime, routes VTK's global output window into this object and mutes the logger that VTK 9
// also sends every error to (it prints to standard error by itself); both are restored afterwards. Not
// thread-safe: VTK's output window is global, so use it around reading and writing files only.
class VtkMessageCapture {
 public:
  VtkMessageCapture();
  ~VtkMessageCapture();
  VtkMessageCapture(const VtkMessageCapture&) = delete;
  VtkMessageCapture& operator=(const VtkMessageCapture&) = delete;

  // The explanations of the errors seen so far, "; "-joined, without VTK's "ERROR: In file, line N" headers
  // and "vtkClass (0x...): " prefixes, and without the pipeline's follow-ups "returned failure for request"
  // and "No update piece number has been set", which say nothing new. Empty when there were none. (Warnings
  // are swallowed: they do not make a file unreadable.)
  const std::string& errors() const;
  // " (VTK: <errors>)" to append to a message, or "" when there were none.
  std::string reason() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hexbite
