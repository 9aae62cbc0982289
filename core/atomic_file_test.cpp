#include "core/atomic_file.h"

#include <unistd.h>

#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
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

}  // namespace
}  // namespace eik
