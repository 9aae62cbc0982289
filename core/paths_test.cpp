#include "core/paths.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/testing.h"

namespace eik {
namespace {

namespace fs = std::filesystem;
using test_support::TempDir;
using test_support::writeFile;

// Restores the default (the rule in force) whatever a test did.
struct OutsidePathsAllowed {
  explicit OutsidePathsAllowed(bool allow) { allowPathsOutsideFolder(allow); }
  ~OutsidePathsAllowed() { allowPathsOutsideFolder(false); }
};

TEST(Paths, ANameBelowTheFolderIsInsideAndEverythingElseIsNot) {
  TempDir dir("eikonal-paths");
  const fs::path folder = dir.path() / "scene";
  fs::create_directories(folder / "sub");
  EXPECT_TRUE(isInsideFolder(folder / "a.nrrd", folder));
  EXPECT_TRUE(isInsideFolder(folder / "sub" / "b.nrrd", folder));
  EXPECT_TRUE(isInsideFolder(folder / "sub" / ".." / "a.nrrd", folder));
  EXPECT_TRUE(isInsideFolder(folder / "not-yet" / "written.nrrd", folder));
  EXPECT_FALSE(isInsideFolder(folder, folder)) << "the folder itself is not a file in it";
  EXPECT_FALSE(isInsideFolder(folder / ".", folder));
  EXPECT_FALSE(isInsideFolder(folder / ".." / "a.nrrd", folder));
  EXPECT_FALSE(isInsideFolder(folder / "sub" / ".." / ".." / "a.nrrd", folder));
  EXPECT_FALSE(isInsideFolder("/etc/passwd", folder));
  EXPECT_FALSE(isInsideFolder(dir.path() / "scene-other" / "a.nrrd", folder)) << "a prefix of a name is not a folder";
}

TEST(Paths, SymlinksAreFollowedBeforeTheCheck) {
  TempDir dir("eikonal-paths");
  const fs::path folder = dir.path() / "scene";
  fs::create_directories(folder);
  writeFile(dir.path() / "secret.txt", "x");
  fs::create_symlink(dir.path() / "secret.txt", folder / "innocent.nrrd");
  fs::create_directory_symlink(dir.path(), folder / "up");
  EXPECT_FALSE(isInsideFolder(folder / "innocent.nrrd", folder)) << "a link in the folder to a file outside it";
  EXPECT_FALSE(isInsideFolder(folder / "up" / "secret.txt", folder)) << "a link to a folder above";
  // The folder reached through a link of its own: its files are still inside.
  fs::create_directory_symlink(folder, dir.path() / "alias");
  writeFile(folder / "a.nrrd", "x");
  EXPECT_TRUE(isInsideFolder(dir.path() / "alias" / "a.nrrd", dir.path() / "alias"));
  EXPECT_TRUE(isInsideFolder(dir.path() / "alias" / "a.nrrd", folder));
}

TEST(Paths, ResolveNamesTheFileAndTheKeyOfAnEscapingPathUnlessTheRuleIsLifted) {
  TempDir dir("eikonal-paths");
  const fs::path source = dir.path() / "scene" / "SCENE.json";
  fs::create_directories(source.parent_path());
  EXPECT_EQ(resolveInsideFolder(source, "objects[0].volume", "a.vol.json"), source.parent_path() / "a.vol.json");
  for (const std::string named : {"../a.vol.json", "/etc/passwd", "sub/../../a.vol.json"}) {
    try {
      resolveInsideFolder(source, "objects[0].volume", named);
      ADD_FAILURE() << named << " was accepted";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(source.string() + ": objects[0].volume: '" + named + "' is outside the folder", 0), 0)
          << what;
      EXPECT_NE(what.find("--allow-outside-paths"), std::string::npos) << what;
    }
  }
  OutsidePathsAllowed allowed(true);
  EXPECT_EQ(resolveInsideFolder(source, "k", "/etc/passwd"), fs::path("/etc/passwd"));
  EXPECT_EQ(resolveInsideFolder(source, "k", "../a"), source.parent_path() / "../a");
}

}  // namespace
}  // namespace eik
