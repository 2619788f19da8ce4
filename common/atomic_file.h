// Writing outputs so that a failed run never leaves a half-written file behind.
#pragma once

#include <functional>
#include <string>
#include <system_error>

namespace hexbite {

// Calls write(tmp_path) with a temporary name next to final_path and renames it to final_path
// when write returns; removes the temporary file if write throws. The directory must exist.
void write_atomically(const std::string& final_path, const std::function<void(const std::string&)>& write);

// Installs handlers for SIGINT, SIGTERM and SIGHUP (Ctrl-C, a batch system's time limit, a closed terminal)
// that remove the temporary files write_atomically is writing, then end the process as the signal would:
// an interrupted write left a hidden '.NAME.tmpPID.vtu' that nothing removed.
void remove_temporary_files_on_signals();

// While it lives, `path` is removed by those handlers too: a file unlinked, a folder (kFolder) removed after
// every registered file and tree when it is empty by then, so a temporary folder whose files are registered
// goes whole, a folder with everything in it (kTree: an output stage, common/output_stage.h). For temporary
// files that write_atomically does not make (the report's pictures). At most 32 paths at once, each shorter
// than 4096 bytes; others are not registered (left behind on a signal).
class RemovedOnSignal {
 public:
  enum Kind { kFile, kFolder, kTree };
  explicit RemovedOnSignal(const std::string& path, Kind kind = kFile);
  ~RemovedOnSignal();
  RemovedOnSignal(const RemovedOnSignal&) = delete;
  RemovedOnSignal& operator=(const RemovedOnSignal&) = delete;

 private:
  int slot_ = -1;
};

// While it lives, SIGINT, SIGTERM and SIGHUP wait: those handlers note the signal and return, and it acts
// when the last SignalsDeferred ends (removing the temporary files registered then, ending the process). For
// moving a set of outputs into place: a signal in the middle left some of them new and some old. Signals
// delivered to any thread wait (a mask would hold them only in the calling thread). Only one thread at a time
// may defer them.
class SignalsDeferred {
 public:
  SignalsDeferred();
  ~SignalsDeferred();
  SignalsDeferred(const SignalsDeferred&) = delete;
  SignalsDeferred& operator=(const SignalsDeferred&) = delete;
};

// The temporary name beside `final_path` that its content is written to first: hidden, with the process id,
// ending in `extension` (the format's, ".vtu" or ".nii.gz": some writers choose the format from it). The
// final name's stem is shortened when the temporary name would be longer than the folder's file system
// allows (a 250-byte name is a valid output; its temporary name with ".tmpPID" added was not).
std::string temporary_path_beside(const std::string& final_path, const std::string& extension);

// Why a write failed when the stream says only that it failed, and what to do.
inline constexpr const char* kWriteFailed = "the disk is full or the file passed a size limit (ulimit -f)";
inline constexpr const char* kWriteAdvice = "make room on the disk or choose another output folder";

// The message for a finished output that could not take the place of `path` (the rename failed with `ec`):
// an immutable file (chattr +i) gave only the system's "Operation not permitted".
std::string replace_refused(const std::string& path, const std::error_code& ec);

// Convenience: writes a whole text or binary string atomically.
void write_file_atomically(const std::string& final_path, const std::string& contents);

}  // namespace hexbite
