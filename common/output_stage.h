// Writing a set of output files all-or-nothing.
//
// Why: write_atomically (common/atomic_file.h) keeps every single file whole, but a command that writes
// several files (hexbite run: results.json, mesh.vtu, the solution files, model.inp) and fails after the
// first of them (disk full, a folder in the way of a file name, a late refusal) left the new files beside
// those of an earlier run in the same folder: a script could read this run's results.json with the last
// run's solution, or the reverse. An OutputStage collects the whole set in a hidden folder inside the
// output folder (so that moving the files into place is a rename on the same file system), and only
// commit() moves it into place; a failure of commit() puts everything back. Whatever fails, the output
// folder ends as it was: the earlier files untouched and, if the folder did not exist, not created.
//
// Ctrl-C, SIGTERM or SIGHUP (common/atomic_file.h) remove the stage, and the output folder when the stage
// made it and it is empty, before the process ends; during a commit they wait for its end, so the output
// folder holds one run's set whole. A process killed otherwise (SIGKILL, a node lost) can leave the hidden
// folder (.hexbite-stage-*) behind; the next stage in the same folder removes it (each live stage holds an
// flock on its folder, so a concurrent run's stage is never taken), unless it holds an earlier run's files
// that the killed commit had set aside, which it names in a warning. Two runs that commit into one folder at
// once take turns (CommitLock): the second replaces the first one's set whole.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/atomic_file.h"

namespace hexbite {

class OutputStage {
 public:
  // Creates `dir` (and its missing parents) when it does not exist, and the stage inside it.
  // Throws RunError naming the folder when either cannot be created.
  explicit OutputStage(const std::string& dir);
  // Discards the stage (and the folders the constructor created) unless commit() succeeded.
  ~OutputStage();
  OutputStage(const OutputStage&) = delete;
  OutputStage& operator=(const OutputStage&) = delete;

  // The output folder as given, and the folder to write the files of the set into (under their final
  // names, e.g. stage_dir() + "/results.json").
  const std::string& dir() const { return dir_; }
  const std::string& stage_dir() const { return stage_; }
  // Whether the constructor created the output folder.
  bool created_dir() const { return !created_.empty(); }

  // Moves the staged `files` (names relative to the folders, in this order) into the output folder,
  // replacing files of those names, and removes the other files of the output folder for which
  // `retire(name)` is true (files of an earlier run that this one does not rewrite). A name may lie in a
  // folder ("soft_bone/results.json": a study's variant): the folder is made in the output folder when it is
  // missing, and `retire` is asked about the files of that folder too, by the same relative names. All or
  // nothing: when a move fails (a folder in the way of a name, a file missing from the stage), everything
  // done is undone and RunError names the file and what to do. Then removes the stage. Holds a CommitLock
  // on the output folder throughout.
  void commit(const std::vector<std::string>& files,
              const std::function<bool(const std::string&)>& retire = nullptr);

  // Why commit(files) would fail for what is in the output folder now (a folder in the way of a file's
  // name, a file where a folder of its path is needed), or empty. commit() asks it before the first move;
  // a command that commits several stages asks every one before the first commit, so that a later stage
  // that cannot be moved in does not leave the earlier ones' files in place.
  std::string blocked(const std::vector<std::string>& files) const;

  // Removes the stage and the folders the constructor created (these only when empty). Never throws.
  void discard() noexcept;

 private:
  // Lets go of the stage's lock (closes its descriptor) and of its removal on a signal.
  void release() noexcept;

  std::string dir_;
  std::string stage_;
  std::vector<std::filesystem::path> created_;  // folders the constructor created, deepest first
  bool done_ = false;                           // committed or discarded
  int lock_ = -1;                               // descriptor of the stage folder holding its flock
  std::vector<std::unique_ptr<RemovedOnSignal>> on_signal_;  // the stage and the folders created
};

// While it lives, the folders `dirs` are locked against the CommitLocks of other processes, which wait for
// it to end (saying so with info(): "waiting for another hexbite process ..."), and SIGINT, SIGTERM and
// SIGHUP wait as well (SignalsDeferred), so that the files moved into them are one run's set whole.
// OutputStage::commit() takes one for its folder; a command that commits several stages takes one for all
// their folders around the commits, so that another run's commits come before or after all of them. Within
// the process it nests: a folder locked already is not waited for. Every process locks the folders in the
// same order (of their device and inode), so two never wait for each other. The lock is an flock on the
// folder; where the file system has none, commits do not wait.
class CommitLock {
 public:
  explicit CommitLock(const std::vector<std::string>& dirs);
  ~CommitLock();
  CommitLock(const CommitLock&) = delete;
  CommitLock& operator=(const CommitLock&) = delete;

 private:
  std::vector<std::pair<dev_t, ino_t>> held_;  // the folders this one locked or counted
  std::optional<SignalsDeferred> deferred_;    // after the locks: a signal while waiting acts at once
};

// A writer's `message` names a file by its place in the stage `stage_dir`; this names it by its place in
// `dir`, where the user looks for it.
std::string named_in_dir(std::string message, const std::string& stage_dir, const std::string& dir);

}  // namespace hexbite
