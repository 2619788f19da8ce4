// OutputStage (common/output_stage.h): a set of files moves into its folder whole or not at all, and a
// failure leaves the folder as it was, the files of an earlier run byte for byte.
#include "common/output_stage.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/helper_threads.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

namespace fs = std::filesystem;

// A thread the system refused (its 8 MB stack beyond an address-space limit) threw std::system_error out of
// the grid mesher's thread pool, whose started threads then ended the process in std::terminate.
TEST(HelperThreads, ARefusedThreadIsReportedAndTheCallerDoesTheWork) {
  std::vector<std::thread> helpers;
  helpers.reserve(2);
  bool ran = false;
  rlimit before{};
  ASSERT_EQ(getrlimit(RLIMIT_AS, &before), 0);
  double mapped_pages = 0;
  std::ifstream("/proc/self/statm") >> mapped_pages;
  ASSERT_GT(mapped_pages, 0);
  rlimit tight = before;
  tight.rlim_cur = static_cast<rlim_t>(mapped_pages * sysconf(_SC_PAGESIZE)) + (1u << 20);  // 1 MB more
  ASSERT_EQ(setrlimit(RLIMIT_AS, &tight), 0);
  const bool started = start_helper_thread(helpers, [&ran] { ran = true; });
  ASSERT_EQ(setrlimit(RLIMIT_AS, &before), 0);
  EXPECT_FALSE(started);
  EXPECT_TRUE(helpers.empty());
  EXPECT_FALSE(ran);
  ASSERT_TRUE(start_helper_thread(helpers, [&ran] { ran = true; }));
  helpers.front().join();
  EXPECT_TRUE(ran);
}

bool is_output(const std::string& name) {
  return name.rfind("out_", 0) == 0;
}

// Ctrl-C or a batch system's SIGTERM while a file was being written left its hidden temporary file, which
// nothing removed (helper K). A child process writes, and is signalled in the middle of the write.
TEST(AtomicFile, ASignalDuringAWriteRemovesTheTemporaryFile) {
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    const std::string dir = test::temp_dir();
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      remove_temporary_files_on_signals();
      write_atomically(dir + "/out.vtu", [&](const std::string& tmp) {
        test::write_file(tmp, "half a file");
        std::raise(signal_number);
      });
      std::_Exit(0);  // not reached: the signal ends the process
    }
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal_number) << signal_number;
    EXPECT_TRUE(fs::is_empty(dir)) << "a temporary file was left, signal " << signal_number;
  }
}

// The report's temporary folder of pictures was left behind on Ctrl-C or SIGTERM (helper P): a registered
// folder goes with its registered files.
TEST(AtomicFile, ASignalRemovesARegisteredFolderWithItsFiles) {
  const std::string dir = test::temp_dir();
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    remove_temporary_files_on_signals();
    fs::create_directory(dir + "/pictures");
    const RemovedOnSignal folder(dir + "/pictures", RemovedOnSignal::kFolder);
    const RemovedOnSignal a(dir + "/pictures/a.png"), b(dir + "/pictures/b.png");
    test::write_file(dir + "/pictures/a.png", "png");
    test::write_file(dir + "/pictures/b.png", "png");
    std::raise(SIGTERM);
    std::_Exit(0);  // not reached
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM);
  EXPECT_TRUE(fs::is_empty(dir)) << "the folder or a picture was left";
}

// A finished file that cannot take the output's place (an immutable file, chattr +i, refuses the rename;
// here a folder of that name, which the commands refuse earlier) gave only the system's text: the message
// says what refused it and what to do, and no temporary file stays.
TEST(AtomicFile, AReplaceThatIsRefusedSaysWhatToDo) {
  const std::string dir = test::temp_dir();
  fs::create_directories(dir + "/out.vtu/inside");
  const std::string msg =
      test::message_of<RunError>([&] { write_file_atomically(dir + "/out.vtu", "a mesh"); });
  EXPECT_EQ(msg.rfind("cannot write '" + dir + "/out.vtu': ", 0), 0u) << msg;
  EXPECT_NE(msg.find("the finished file could not take its place: an immutable file, which lsattr marks 'i' "
                     "and chattr -i frees, or a read-only mount refuse it); free the file or choose another "
                     "output name"),
            std::string::npos)
      << msg;
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

TEST(OutputStage, CommitMovesTheSetInAndRemovesTheEarlierRunsOtherOutputs) {
  const std::string dir = test::temp_dir();
  test::write_file(dir + "/out_a", "old a\n");
  test::write_file(dir + "/out_stale", "old stale\n");
  test::write_file(dir + "/notes.txt", "mine\n");
  fs::create_directory(dir + "/out_folder");  // a folder of an output's name is no output: it stays
  {
    OutputStage stage(dir);
    EXPECT_FALSE(stage.created_dir());
    EXPECT_EQ(fs::path(stage.stage_dir()).parent_path(), fs::path(dir));
    test::write_file(stage.stage_dir() + "/out_a", "new a\n");
    test::write_file(stage.stage_dir() + "/out_b", "new b\n");
    EXPECT_FALSE(fs::exists(dir + "/out_b"));  // nothing moves before commit
    stage.commit({"out_a", "out_b"}, is_output);
  }
  const std::map<std::string, std::string> expected = {
      {"out_a", "new a\n"}, {"out_b", "new b\n"}, {"notes.txt", "mine\n"}, {"out_folder", "<folder>"}};
  EXPECT_EQ(test::files_under(dir), expected);
}

// Names in folders (a study's variants, "v1/out_a"): the folder is made when missing, the earlier run's
// outputs in it are retired by their relative names, and a failure removes the folders the commit made.
TEST(OutputStage, NamesInFoldersAreCommittedAndUndoneWithTheirFolders) {
  const std::string dir = test::temp_dir();
  fs::create_directory(dir + "/v1");
  test::write_file(dir + "/v1/out_stale", "old stale\n");
  test::write_file(dir + "/v1/notes.txt", "mine\n");
  const auto in_folder_output = [](const std::string& name) {
    return name.find('/') != std::string::npos && is_output(name.substr(name.find('/') + 1));
  };
  {
    OutputStage stage(dir);
    for (const char* name : {"v1", "v2"}) fs::create_directory(stage.stage_dir() + "/" + name);
    test::write_file(stage.stage_dir() + "/v1/out_a", "new v1\n");
    test::write_file(stage.stage_dir() + "/v2/out_a", "new v2\n");
    stage.commit({"v1/out_a", "v2/out_a"}, in_folder_output);
  }
  const std::map<std::string, std::string> expected = {{"v1", "<folder>"},
                                                       {"v1/out_a", "new v1\n"},
                                                       {"v1/notes.txt", "mine\n"},
                                                       {"v2", "<folder>"},
                                                       {"v2/out_a", "new v2\n"}};
  EXPECT_EQ(test::files_under(dir), expected);

  // v3's file is missing from the stage: v1's file returns, and the folder v2b that the commit made goes.
  {
    OutputStage stage(dir);
    for (const char* name : {"v1", "v2b"}) fs::create_directory(stage.stage_dir() + "/" + name);
    test::write_file(stage.stage_dir() + "/v1/out_a", "newer v1\n");
    test::write_file(stage.stage_dir() + "/v2b/out_a", "new v2b\n");
    const std::string message = test::message_of<RunError>([&] {
      stage.commit({"v1/out_a", "v2b/out_a", "v3/out_a"}, in_folder_output);
    });
    EXPECT_NE(message.find("v3/out_a"), std::string::npos) << message;
  }
  EXPECT_EQ(test::files_under(dir), expected);
}

// The last file's name is taken by a folder: the files already moved go back, the earlier ones return.
TEST(OutputStage, AFolderInTheWayOfTheLastFileLeavesTheFolderAsItWas) {
  const std::string dir = test::temp_dir();
  test::write_file(dir + "/out_a", "old a\n");
  test::write_file(dir + "/out_stale", "old stale\n");
  fs::create_directory(dir + "/out_c");
  test::write_file(dir + "/out_c/inside", "mine\n");
  const std::map<std::string, std::string> before = test::files_under(dir);
  std::string message;
  {
    OutputStage stage(dir);
    for (const char* name : {"out_a", "out_b", "out_c"})
      test::write_file(stage.stage_dir() + "/" + name, std::string("new ") + name + "\n");
    message = test::message_of<RunError>([&] { stage.commit({"out_a", "out_b", "out_c"}, is_output); });
  }
  EXPECT_NE(message.find("cannot write '" + dir +
                         "/out_c': a folder of that name is in the way; remove or "
                         "rename it, or choose another output folder"),
            std::string::npos)
      << message;
  test::expect_same_files(before, test::files_under(dir));  // no stage left either
}

// A file that a writer (another rank) should have put into the stage and did not.
TEST(OutputStage, AFileMissingFromTheStageIsRefusedAndNothingMoves) {
  const std::string dir = test::temp_dir();
  test::write_file(dir + "/out_a", "old a\n");
  const std::map<std::string, std::string> before = test::files_under(dir);
  OutputStage stage(dir);
  test::write_file(stage.stage_dir() + "/out_a", "new a\n");
  const std::string message = test::message_of<RunError>([&] {
    stage.commit({"out_a", "out_missing"}, is_output);
  });
  EXPECT_NE(message.find("cannot write '" + dir + "/out_missing': it was not written"), std::string::npos)
      << message;
  test::expect_same_files(before, test::files_under(dir));
}

// A run killed while it wrote (Ctrl-C, SIGKILL) leaves its stage behind, and stages piled up. The next
// stage in the folder removes it, but never a live run's stage (it holds the stage's lock), one just made
// (perhaps not locked yet), nor an earlier run's files that an interrupted commit had set aside.
TEST(OutputStage, AnAbandonedStageIsRemovedByTheNextOne) {
  const std::string dir = test::temp_dir();
  const auto hour_ago = fs::file_time_type::clock::now() - std::chrono::hours(1);
  for (const char* stage : {"killed", "justmade", "midcommit/.previous"})
    fs::create_directories(dir + "/.hexbite-stage-" + stage);
  test::write_file(dir + "/.hexbite-stage-killed/out_a", "half\n");
  fs::last_write_time(dir + "/.hexbite-stage-killed", hour_ago);
  test::write_file(dir + "/.hexbite-stage-justmade/out_a", "half\n");
  test::write_file(dir + "/.hexbite-stage-midcommit/.previous/out_a", "the earlier run's a\n");
  fs::last_write_time(dir + "/.hexbite-stage-midcommit", hour_ago);
  OutputStage live(dir);
  test::write_file(live.stage_dir() + "/out_a", "live a\n");
  fs::last_write_time(live.stage_dir(), hour_ago);

  testing::internal::CaptureStderr();
  { OutputStage next(dir); }
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_FALSE(fs::exists(dir + "/.hexbite-stage-killed"));
  EXPECT_TRUE(fs::exists(dir + "/.hexbite-stage-justmade/out_a"));
  EXPECT_TRUE(fs::exists(dir + "/.hexbite-stage-midcommit/.previous/out_a"));
  EXPECT_NE(err.find("hexbite: warning: '" + dir +
                     "/.hexbite-stage-midcommit/.previous' holds files of an earlier run"),
            std::string::npos)
      << err;
  live.commit({"out_a"}, is_output);
  EXPECT_EQ(test::read_file(dir + "/out_a"), "live a\n");
}

// Runs `body` in a child process, which exits 0 when it returns and 1 when it throws; returns its id.
pid_t fork_child(const std::function<void()>& body) {
  const pid_t child = fork();
  if (child != 0) return child;
  try {
    body();
  } catch (...) {
    std::_Exit(1);
  }
  std::_Exit(0);
}

int wait_for(pid_t child) {
  int status = 0;
  EXPECT_EQ(waitpid(child, &status, 0), child);
  return status;
}

// Two runs into one folder at once: the moves were not locked across runs, and a run whose commit came in
// the middle of another's left one's mesh.vtu beside the other's results.json, both exit 0 (hunt U1). Here
// the second commit starts while the first one lists the folder: it waits, then replaces the whole set.
TEST(OutputStage, ASecondCommitIntoTheFolderWaitsAndReplacesTheWholeSet) {
  const std::string dir = test::temp_dir();
  test::write_file(dir + "/notes.txt", "mine\n");
  int go[2];
  ASSERT_EQ(pipe(go), 0);
  const pid_t child = fork_child([&] {
    OutputStage stage(dir);
    for (const char* name : {"out_a", "out_b", "out_c"})
      test::write_file(stage.stage_dir() + "/" + name, std::string("second ") + name + "\n");
    char byte = 0;
    if (read(go[0], &byte, 1) != 1) throw std::runtime_error("no go");
    stage.commit({"out_a", "out_b", "out_c"}, is_output);
  });
  ASSERT_GT(child, 0);
  {
    OutputStage stage(dir);
    for (const char* name : {"out_a", "out_b"})
      test::write_file(stage.stage_dir() + "/" + name, std::string("first ") + name + "\n");
    bool started = false;
    stage.commit({"out_a", "out_b"}, [&](const std::string& name) {
      if (!started) {  // the second run's commit starts now, and has the time to finish
        started = true;
        EXPECT_EQ(write(go[1], "x", 1), 1);
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
      }
      return is_output(name);
    });
  }
  const int status = wait_for(child);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  const std::map<std::string, std::string> second = {{"out_a", "second out_a\n"},
                                                     {"out_b", "second out_b\n"},
                                                     {"out_c", "second out_c\n"},
                                                     {"notes.txt", "mine\n"}};
  EXPECT_EQ(test::files_under(dir), second);
  close(go[0]);
  close(go[1]);
}

// generate commits up to three folders: another generate's commit came between its surface's folder and
// its DICOM folder. A CommitLock over all of them holds off another process's commit into any.
TEST(OutputStage, ACommitWaitsWhileAnotherProcessHoldsItsFolderWithOthers) {
  const std::string one = test::temp_dir(), two = test::temp_dir();
  int go[2];
  ASSERT_EQ(pipe(go), 0);
  const pid_t child = fork_child([&] {  // before the lock: a child would share its descriptors
    OutputStage stage(two);
    test::write_file(stage.stage_dir() + "/out_a", "a\n");
    char byte = 0;
    if (read(go[0], &byte, 1) != 1) throw std::runtime_error("no go");
    std::ofstream said(one + "/said.txt");
    std::streambuf* const terminal = std::cout.rdbuf(said.rdbuf());
    stage.commit({"out_a"}, is_output);
    std::cout.rdbuf(terminal);
  });
  {
    const CommitLock locked({one, two});
    EXPECT_EQ(write(go[1], "x", 1), 1);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_FALSE(fs::exists(two + "/out_a")) << "the commit did not wait";
  }
  close(go[0]);
  close(go[1]);
  ASSERT_GT(child, 0);
  const int status = wait_for(child);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  EXPECT_EQ(test::read_file(two + "/out_a"), "a\n");
  // A run held up by another printed nothing, however long the other took (hunt U, noticed).
  EXPECT_EQ(test::read_file(one + "/said.txt"),
            "waiting for another hexbite process to finish writing into '" + two + "'\n");
}

// Ctrl-C, SIGTERM or SIGHUP in the middle of the moves left the new mesh.vtu beside the old solution.vtu
// and results.json, or no solution.vtu at all (hunt U2). A signal during the commit waits for its end, on
// whichever thread it comes (a process's signal goes to any thread that does not block it).
TEST(OutputStage, ASignalDuringTheCommitActsWhenTheSetIsWhole) {
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP})
    for (bool other_thread : {false, true}) {
      const std::string dir = test::temp_dir();
      test::write_file(dir + "/out_a", "old a\n");
      test::write_file(dir + "/out_stale", "old stale\n");
      const pid_t child = fork_child([&] {
        remove_temporary_files_on_signals();
        OutputStage stage(dir);
        test::write_file(stage.stage_dir() + "/out_a", "new a\n");
        test::write_file(stage.stage_dir() + "/out_b", "new b\n");
        bool raised = false;
        stage.commit({"out_a", "out_b"}, [&](const std::string& name) {
          if (!raised) {
            raised = true;
            if (other_thread)
              std::thread([&] { std::raise(signal_number); }).join();
            else
              std::raise(signal_number);
          }
          return is_output(name);
        });
      });
      ASSERT_GT(child, 0);
      const int status = wait_for(child);
      EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal_number)
          << "signal " << signal_number << (other_thread ? " on another thread" : "");
      const std::map<std::string, std::string> whole = {{"out_a", "new a\n"}, {"out_b", "new b\n"}};
      EXPECT_EQ(test::files_under(dir), whole) << "signal " << signal_number;
    }
}

// A signal while the files were written into the stage left the stage, with its files and folders (a
// study's variants, a DICOM series), and the output folder that the run had created (hunt U10).
TEST(OutputStage, ASignalBeforeTheCommitRemovesTheStageAndTheFoldersItCreated) {
  for (bool existing : {false, true}) {
    const std::string root = test::temp_dir();
    const std::string dir = root + "/new/out";
    if (existing) {
      fs::create_directories(dir);
      test::write_file(dir + "/notes.txt", "mine\n");
    }
    const std::map<std::string, std::string> before = test::files_under(root);
    const pid_t child = fork_child([&] {
      remove_temporary_files_on_signals();
      OutputStage stage(dir);
      for (int i = 1; i <= 86; ++i) test::write_file(stage.stage_dir() + "/ct_" + std::to_string(i), "slice");
      OutputStage variant(stage.stage_dir() + "/v1");  // a study's variant, staged in the study's stage
      test::write_file(variant.stage_dir() + "/out_a", "a\n");
      write_atomically(variant.stage_dir() + "/out_b", [&](const std::string& tmp) {
        test::write_file(tmp, "half");
        std::raise(SIGTERM);
      });
    });
    ASSERT_GT(child, 0);
    const int status = wait_for(child);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM);
    EXPECT_EQ(test::files_under(root), before) << (existing ? "existing folder" : "new folder");
  }
}

// A folder that did not exist (nor its parent) is gone again when the set is given up.
TEST(OutputStage, AGivenUpSetLeavesNoFolderItCreated) {
  const std::string root = test::temp_dir();
  const std::string dir = root + "/new/out/";
  {
    OutputStage stage(dir);
    EXPECT_TRUE(stage.created_dir());
    EXPECT_EQ(stage.dir(), root + "/new/out");
    test::write_file(stage.stage_dir() + "/out_a", "new a\n");
  }  // not committed
  EXPECT_TRUE(fs::is_empty(root));
  {
    OutputStage stage(dir);
    test::write_file(stage.stage_dir() + "/out_a", "new a\n");
    stage.commit({"out_a"}, is_output);
  }
  EXPECT_EQ(test::files_under(root + "/new/out"), (std::map<std::string, std::string>{{"out_a", "new a\n"}}));
}

TEST(OutputStage, AnOutputFolderThatCannotBeCreatedIsNamed) {
  const std::string root = test::temp_dir();
  test::write_file(root + "/file", "x\n");
  const std::string message = test::message_of<RunError>([&] { OutputStage stage(root + "/file/out"); });
  EXPECT_NE(message.find("cannot create the output folder '" + root + "/file/out'"), std::string::npos)
      << message;
}

}  // namespace
}  // namespace hexbite
