#include "mesher/vtk_messages.h"

#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkSmartPointer.h>

#include <algorithm>

namespace hexbite {

namespace {

// VTK's text is "ERROR: In file.cxx, line N\nvtkClass (0x...): explanation\n\n"; keeps the explanation.
void append_explanation(std::string& list, const char* text) {
  if (text == nullptr) return;
  std::string t(text);
  if (t.rfind("ERROR: In ", 0) == 0 || t.rfind("Warning: In ", 0) == 0)
    t = t.substr(std::min(t.size(), t.find('\n') + 1));
  if (const std::size_t object = t.find("): "); object != std::string::npos) t = t.substr(object + 3);
  t = t.substr(0, t.find('\n'));
  if (t.empty() || t.find("returned failure for request") != std::string::npos) return;
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

}  // namespace hexbite
