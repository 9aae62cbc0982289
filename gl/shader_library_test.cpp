// Tests of gl/shader_library and gl/shader_source: search path, embedded copy, #include (once,
// cycles, missing files), defines after #version, and compile errors reported as file:line.
#include "gl/shader_library.h"

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "core/testing.h"
#include "gl/test_util.h"

namespace eik::gl {
namespace {

using test_support::ScopedEnv;
using test_support::TempDir;
using test_support::writeFile;

ShaderLibraryOptions onlyDirectory(const std::filesystem::path& directory) {
  ShaderLibraryOptions options;
  options.directories = {directory};
  options.environment = false;
  options.sourceTree = false;
  options.embedded = false;
  return options;
}

std::string compileError(const ShaderLibrary& library, const std::string& fragment, const ShaderDefines& defines = {}) {
  try {
    library.program("common/fullscreen.vert", fragment, defines);
  } catch (const RuntimeError& e) {
    return e.what();
  }
  return "";
}

class ShaderLibraryGl : public ::testing::Test {
 protected:
  GlContext context_{ContextOptions{.backend = glBackendFromEnvironment(GlBackend::OSMesa), .debug = true}};
};

TEST(ShaderSourceTest, TranslatesMesaNvidiaAndAmdLogs) {
  ShaderSource source;
  source.files = {"test/main.frag", "common/x.glsl", "<defines>"};
  EXPECT_EQ(source.translateLog("0:12(5): error: `foo' undeclared"), "test/main.frag:12:5: error: `foo' undeclared");
  EXPECT_EQ(source.translateLog("1:3(10): error: syntax error\n2:1(1): warning: x"),
            "common/x.glsl:3:10: error: syntax error\n<defines>:1:1: warning: x");
  EXPECT_EQ(source.translateLog("1(7) : error C1008: undefined variable \"a\""),
            "common/x.glsl:7: error C1008: undefined variable \"a\"");
  EXPECT_EQ(source.translateLog("ERROR: 1:9: 'x' : undeclared identifier"),
            "ERROR: common/x.glsl:9: 'x' : undeclared identifier");
  EXPECT_EQ(source.translateLog("7:2(1): error: y"), "<source 7>:2:1: error: y");
  EXPECT_EQ(source.translateLog("no location here"), "no location here");
}

TEST(ShaderSourceTest, StageFromPath) {
  EXPECT_EQ(stageFromPath("a/b.vert"), ShaderStage::Vertex);
  EXPECT_EQ(stageFromPath("b.frag"), ShaderStage::Fragment);
  EXPECT_EQ(stageFromPath("b.geom"), ShaderStage::Geometry);
  EXPECT_THROW(stageFromPath("b.glsl"), RuntimeError);
}

TEST(ShaderLibraryTest, DefinesGoRightAfterVersionAndIncludesAreExpanded) {
  ShaderLibrary library;
  ShaderSource source = library.source("test/pattern.frag", {{"MODE", "1"}, {"EMPTY", ""}}, "const int kPrelude = 3;");
  std::istringstream lines(source.text);
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "#version 330 core");
  std::getline(lines, line);
  EXPECT_EQ(line.rfind("#line 1 ", 0), 0u) << line;
  std::getline(lines, line);
  EXPECT_EQ(line, "#define MODE 1");
  std::getline(lines, line);
  EXPECT_EQ(line, "#define EMPTY");
  std::getline(lines, line);
  EXPECT_EQ(line, "const int kPrelude = 3;");
  EXPECT_NE(source.text.find("float checker(vec2 fragCoord, float cell)"), std::string::npos);
  EXPECT_FALSE(std::regex_search(source.text, std::regex(R"((^|\n)\s*#\s*include)"))) << source.text;
  ASSERT_GE(source.files.size(), 3u);
  EXPECT_EQ(source.files[0], "test/pattern.frag");
  EXPECT_NE(std::find(source.files.begin(), source.files.end(), "test/checker.glsl"), source.files.end());
  EXPECT_NE(std::find(source.files.begin(), source.files.end(), "common/constants.glsl"), source.files.end());
}

TEST(ShaderLibraryTest, FileWithoutVersionGets330Core) {
  ShaderLibrary library;
  ShaderSource source = library.source("test/fetch3d.frag", {{"USE_SAMPLER", "1"}});
  EXPECT_EQ(source.text.rfind("#version 330 core\n#line 1 1\n#define USE_SAMPLER 1\n#line 1 0\n", 0), 0u)
      << source.text.substr(0, 120);
}

TEST(ShaderLibraryTest, RejectsBadPathsAndDefines) {
  ShaderLibrary library;
  EXPECT_THROW(library.read("../CMakeLists.txt"), RuntimeError);
  EXPECT_THROW(library.read("/etc/passwd"), RuntimeError);
  EXPECT_THROW(library.source("test/pattern.frag", {{"1BAD", "x"}}), RuntimeError);
  EXPECT_THROW(library.source("test/pattern.frag", {{"A", "two\nlines"}}), RuntimeError);
  try {
    library.read("test/does_not_exist.frag");
    FAIL();
  } catch (const RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find("test/does_not_exist.frag"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("embedded"), std::string::npos) << e.what();
  }
}

TEST(ShaderLibraryTest, IncludeCycleIsReported) {
  TempDir dir;
  writeFile(dir / "common/a.glsl", "// a\n#include \"common/b.glsl\"\n");
  writeFile(dir / "common/b.glsl", "// b\n\n#include \"../common/a.glsl\"\n");
  writeFile(dir / "test/main.frag", "#version 330 core\n#include \"common/a.glsl\"\nvoid main() {}\n");
  ShaderLibrary library(onlyDirectory(dir.path()));
  try {
    library.source("test/main.frag");
    FAIL() << "no exception";
  } catch (const RuntimeError& e) {
    std::string message = e.what();
    EXPECT_NE(message.find("common/b.glsl:3"), std::string::npos) << message;
    EXPECT_NE(message.find("cycle"), std::string::npos) << message;
    EXPECT_NE(message.find("test/main.frag -> common/a.glsl -> common/b.glsl -> common/a.glsl"), std::string::npos)
        << message;
  }
}

TEST(ShaderLibraryTest, MissingIncludeNamesTheIncludingLine) {
  TempDir dir;
  writeFile(dir / "test/main.frag", "#version 330 core\n\n#include \"common/nowhere.glsl\"\n");
  ShaderLibrary library(onlyDirectory(dir.path()));
  try {
    library.source("test/main.frag");
    FAIL() << "no exception";
  } catch (const RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find("test/main.frag:3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("common/nowhere.glsl"), std::string::npos) << e.what();
  }
}

TEST_F(ShaderLibraryGl, EachFileIsIncludedOnce) {
  TempDir dir;
  writeFile(dir / "common/fullscreen.vert", ShaderLibrary().read("common/fullscreen.vert"));
  writeFile(dir / "common/f.glsl", "#pragma once\nfloat f() { return 1.0; }\n");
  writeFile(dir / "common/g.glsl", "#include \"common/f.glsl\"\nfloat g() { return f(); }\n");
  writeFile(dir / "test/main.frag",
            "#version 330 core\n#include \"common/f.glsl\"\n#include \"common/g.glsl\"\n#include \"common/f.glsl\"\n"
            "out vec4 o;\nvoid main() { o = vec4(f() + g()); }\n");
  ShaderLibrary library(onlyDirectory(dir.path()));
  EXPECT_NO_THROW(library.program("common/fullscreen.vert", "test/main.frag"));
}

TEST_F(ShaderLibraryGl, CompileErrorInAnIncludedFileNamesFileAndLine) {
  TempDir dir;
  writeFile(dir / "common/fullscreen.vert", ShaderLibrary().read("common/fullscreen.vert"));
  writeFile(dir / "common/helpers.glsl",
            "// helpers\n"
            "float helperOk() { return 1.0; }\n"
            "\n"
            "float helperBroken() { return undefinedThing; }\n");  // line 4
  writeFile(dir / "test/broken.frag",
            "#version 330 core\n"
            "// a comment\n"
            "#include \"common/helpers.glsl\"\n"
            "out vec4 o;\n"
            "void main() { o = vec4(helperOk()); }\n");
  ShaderLibrary library(onlyDirectory(dir.path()));
  std::string message = compileError(library, "test/broken.frag", {{"MODE", "1"}, {"OTHER", "2"}});
  EXPECT_NE(message.find("could not compile fragment shader test/broken.frag"), std::string::npos) << message;
  EXPECT_NE(message.find("common/helpers.glsl:4:"), std::string::npos) << message;
  EXPECT_NE(message.find("undefinedThing"), std::string::npos) << message;

  // An error in the main file after the include: the line count resumes correctly.
  writeFile(dir / "test/broken2.frag",
            "#version 330 core\n"
            "#include \"common/helpers.glsl\"\n"
            "out vec4 o;\n"
            "void main() {\n"
            "  o = vec4(nope);\n"  // line 5
            "}\n");
  writeFile(dir / "common/helpers.glsl", "float helperOk() { return 1.0; }\n");
  message = compileError(library, "test/broken2.frag", {{"MODE", "1"}});
  EXPECT_NE(message.find("test/broken2.frag:5:"), std::string::npos) << message;

  // An error in the injected prelude: reported as <defines>, line 2 after one define.
  try {
    library.program("common/fullscreen.vert", "test/broken2.frag", {{"A", "1"}}, "float preludeBroken = ;");
    FAIL() << "no exception";
  } catch (const RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find("<defines>:2:"), std::string::npos) << e.what();
  }

  // A define selecting an #error branch in the real tree.
  message = compileError(ShaderLibrary(), "test/pattern.frag", {{"MODE", "3"}});
  EXPECT_NE(message.find("test/pattern.frag:"), std::string::npos) << message;
  EXPECT_NE(message.find("MODE must be 1 or 2"), std::string::npos) << message;
}

TEST_F(ShaderLibraryGl, EmbeddedCopyIsUsedWhenTheDirectoriesAreHidden) {
  TempDir empty;
  ScopedEnv dir("EIKONAL_SHADER_DIR", empty.path().c_str());
  ShaderLibraryOptions options;
  options.sourceTree = false;
  ShaderLibrary library(options);
  EXPECT_EQ(library.locate("test/pattern.frag"), "embedded:test/pattern.frag");
  EXPECT_EQ(library.locate("common/fullscreen.vert"), "embedded:common/fullscreen.vert");
  // The embedded copy is the source tree's file, byte for byte (regenerated when a shader changes).
  std::ifstream file(ShaderLibrary::sourceTreeDirectory() / "test/pattern.frag", std::ios::binary);
  std::stringstream disk;
  disk << file.rdbuf();
  EXPECT_EQ(library.read("test/pattern.frag"), disk.str());
  std::vector<std::string> files = ShaderLibrary::embeddedFiles();
  EXPECT_NE(std::find(files.begin(), files.end(), "common/volume.glsl"), files.end());
  // And it renders.
  test::renderAndCheckPattern(32, 24);
}

TEST_F(ShaderLibraryGl, EmbeddedOnlyEnvironmentSkipsTheDisk) {
  TempDir dir;
  writeFile(dir / "test/pattern.frag", "this is not GLSL");
  ScopedEnv shaderDir("EIKONAL_SHADER_DIR", dir.path().c_str());
  {
    ShaderLibrary library;  // EIKONAL_SHADER_DIR first: the broken override wins
    EXPECT_EQ(library.locate("test/pattern.frag"), (dir.path() / "test/pattern.frag").string());
    EXPECT_EQ(library.read("test/pattern.frag"), "this is not GLSL");
    // Files it lacks come from the next place on the search path.
    EXPECT_NE(library.locate("test/checker.glsl"), "embedded:test/checker.glsl");
  }
  ScopedEnv embeddedOnly("EIKONAL_SHADERS_EMBEDDED_ONLY", "1");
  ShaderLibrary library;
  EXPECT_TRUE(library.directories().empty());
  EXPECT_EQ(library.locate("test/pattern.frag"), "embedded:test/pattern.frag");
  EXPECT_EQ(library.locate("test/checker.glsl"), "embedded:test/checker.glsl");
  test::renderAndCheckPattern(16, 8);
}

}  // namespace
}  // namespace eik::gl
