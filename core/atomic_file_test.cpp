#include "core/atomic_file.h"

#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>

#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/interrupt.h"
#include "core/testing.h"

namespace eik {
namespace {
namespace fs = std::filesystem;

using test_support::readFile;
using test_support::TempDir;

TEST(AtomicFile, WriteFileAtomicCreatesAndReplaces) {
  TempDir dir;
  writeFileAtomic(dir / "a.json", "first");
  EXPECT_EQ(readFile(dir / "a.json"), "first");
  writeFileAtomic(dir / "a.json", "second, longer");
  EXPECT_EQ(readFile(dir / "a.json"), "second, longer");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"a.json"});
}

TEST(AtomicFile, TemporaryNameIsHiddenBesideTheTarget) {
  fs::path target = fs::path("some/dir") / "out.vol.json";
  fs::path temporary = temporaryPathFor(target);
  EXPECT_EQ(temporary.parent_path(), target.parent_path());
  std::string prefix = ".out.vol.json.tmp-" + std::to_string(::getpid()) + "-";
  EXPECT_EQ(temporary.filename().string().rfind(prefix, 0), 0u) << temporary;
  EXPECT_NE(temporaryPathFor(target), temporary);  // unique per call
}

TEST(AtomicFile, NothingAppearsBeforeCommit) {
  TempDir dir;
  AtomicFileSet files;
  files.write(dir / "a.nrrd", "A");
  files.write(dir / "b.vol.json", "B");
  EXPECT_FALSE(fs::exists(dir / "a.nrrd"));
  EXPECT_FALSE(fs::exists(dir / "b.vol.json"));
  EXPECT_EQ(dir.entries().size(), 2u);  // two hidden temporaries
  files.commit();
  EXPECT_TRUE(files.committed());
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"a.nrrd", "b.vol.json"}));
  EXPECT_EQ(readFile(dir / "a.nrrd"), "A");
  EXPECT_EQ(readFile(dir / "b.vol.json"), "B");
}

TEST(AtomicFile, AbandonedSetLeavesNothingBehind) {
  TempDir dir;
  writeFileAtomic(dir / "keep.txt", "old");
  EXPECT_THROW(
      {
        AtomicFileSet files;
        files.write(dir / "keep.txt", "new");
        files.write(dir / "other.txt", "x");
        throw std::runtime_error("interrupted mid-write");
      },
      std::runtime_error);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.txt"});
  EXPECT_EQ(readFile(dir / "keep.txt"), "old");
}

TEST(AtomicFile, StagedButNeverCreatedIsFine) {
  TempDir dir;
  {
    AtomicFileSet files;
    fs::path temporary = files.stage(dir / "x.bin");
    EXPECT_FALSE(fs::exists(temporary));
  }
  EXPECT_TRUE(dir.entries().empty());
}

TEST(AtomicFile, MissingDirectoryIsAnInputErrorNamingTheFile) {
  TempDir dir;
  fs::path target = dir / "no-such-dir" / "out.png";
  try {
    writeFileAtomic(target, "x");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(target.string()), std::string::npos) << e.what();
  }
  EXPECT_TRUE(dir.entries().empty());
}

TEST(AtomicFile, StagingOneTargetTwiceIsRejected) {
  TempDir dir;
  AtomicFileSet files;
  files.stage(dir / "a");
  EXPECT_THROW(files.stage(dir / "a"), RuntimeError);
}

TEST(AtomicFile, MovedSetOwnsTheTemporaries) {
  TempDir dir;
  AtomicFileSet outer;
  {
    AtomicFileSet inner;
    inner.write(dir / "a", "A");
    outer = std::move(inner);
  }
  EXPECT_EQ(dir.entries().size(), 1u);  // the moved-from set removed nothing
  outer.commit();
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"a"});
}

// SIGTERM and SIGINT in the middle of a multi-file write (core/interrupt.h): the process ends with
// 128 + the signal, says so, and leaves neither a temporary nor a target; an older target stays.
void interruptMidWrite(const fs::path& dir, int signal_number) {
  installInterruptHandlers("atomic_file_test");
  AtomicFileSet files;
  files.write(dir / "field.nrrd", "new field");
  files.write(dir / "out.vol.json", "new manifest");
  std::raise(signal_number);
  std::_Exit(0);  // not reached: the handler exits
}

TEST(AtomicFileDeathTest, SigtermRemovesTheTemporariesAndExits143) {
  TempDir dir;
  writeFileAtomic(dir / "out.vol.json", "old manifest");
  EXPECT_EXIT(interruptMidWrite(dir.path(), SIGTERM), testing::ExitedWithCode(143),
              "atomic_file_test: terminated \\(SIGTERM\\); no output written");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.vol.json"});
  EXPECT_EQ(readFile(dir / "out.vol.json"), "old manifest");
}

TEST(AtomicFileDeathTest, SigintRemovesTheTemporariesAndExits130) {
  TempDir dir;
  EXPECT_EXIT(interruptMidWrite(dir.path(), SIGINT), testing::ExitedWithCode(130), "interrupted \\(SIGINT\\)");
  EXPECT_TRUE(dir.entries().empty());
}

TEST(AtomicFile, StagedTemporariesAreRegisteredForTheSignalHandlerUntilCommitOrDiscard) {
  TempDir dir;
  const int before = pending_temporaries::count();
  {
    AtomicFileSet files;
    files.write(dir / "a.txt", "A");
    files.write(dir / "b.txt", "B");
    EXPECT_EQ(pending_temporaries::count(), before + 2);
    files.commit();
    EXPECT_EQ(pending_temporaries::count(), before);
  }
  {
    AtomicFileSet files;
    files.write(dir / "c.txt", "C");
    EXPECT_EQ(pending_temporaries::count(), before + 1);
  }
  EXPECT_EQ(pending_temporaries::count(), before);
  // A path too long for the table is not registered (the normal path still removes it).
  EXPECT_EQ(pending_temporaries::add(std::string(pending_temporaries::kPathBytes, 'x')), -1);
}

TEST(AtomicFile, TemporariesOfDeadProcessesAreRemovedByTheNextWrite) {
  TempDir dir;
  // A process that has exited: a child reaped here, so its pid is free (and not ours).
  const pid_t child = ::fork();
  if (child == 0) std::_Exit(0);
  ASSERT_GT(child, 0);
  ::waitpid(child, nullptr, 0);
  const std::string dead = ".out.nrrd.tmp-" + std::to_string(child) + "-0123456789abcdef";
  const std::string alive = ".out.nrrd.tmp-" + std::to_string(::getppid()) + "-0123456789abcdef";  // our parent
  const std::string other = ".other.nrrd.tmp-" + std::to_string(child) + "-0123456789abcdef";    // another target
  for (const std::string& name : {dead, alive, other}) test_support::writeFile(dir / name, "partial");
  writeFileAtomic(dir / "out.nrrd", "complete");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{other, alive, "out.nrrd"}));  // sorted
}

}  // namespace
}  // namespace eik
