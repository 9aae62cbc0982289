// Paths inside files stay inside the folder of the file that names them (issue "Reliability";
// docs/programs.md "Paths inside files"). For every key that names a file, a `../` path and an
// absolute path to a valid file outside the folder are refused with exit 2 naming the key, and
// the outside file is never opened: inotify watches it (IN_OPEN, IN_ACCESS), and the same run with
// --allow-outside-paths must open it, which shows the watch sees the program's opens.
#include <sys/inotify.h>
#include <unistd.h>

#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/image_io.h"
#include "tests/program_runner.h"

namespace eik::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Has any process opened or read `path` since construction?
class OpenWatch {
 public:
  explicit OpenWatch(const fs::path& path) : fd_(::inotify_init1(IN_NONBLOCK | IN_CLOEXEC)) {
    if (fd_ < 0 || ::inotify_add_watch(fd_, path.c_str(), IN_OPEN | IN_ACCESS) < 0)
      throw std::runtime_error("inotify cannot watch " + path.string());
  }
  ~OpenWatch() { ::close(fd_); }
  OpenWatch(const OpenWatch&) = delete;
  OpenWatch& operator=(const OpenWatch&) = delete;
  bool opened() const {
    alignas(inotify_event) char buffer[4096];
    return ::read(fd_, buffer, sizeof buffer) > 0;  // any event; EAGAIN when none
  }

 private:
  int fd_;
};

// DIR/outside/ holds valid files; DIR/in/ the input that names one of them.
class PathsCli : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(in());
    fs::create_directories(outside());
    ProgramResult r = runProgram(VOXELIZE_EXE,
                                 {"procedural:sphere,r=0.5,ior=1.5", "-o", "ball.vol.json", "--res", "8", "--quiet"},
                                 outside());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = runProgram(VOXELIZE_EXE,
                   {"procedural:sphere,r=0.5,ior=1.5", "-o", "ball.vol.json", "--res", "8", "--quiet"}, in());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  fs::path in() const { return dir_.path() / "in"; }
  fs::path outside() const { return dir_.path() / "outside"; }
  json manifest(const fs::path& folder) const { return json::parse(readFile(folder / "ball.vol.json")); }
  fs::path outsideField(const std::string& field) const {
    return outside() / manifest(outside())["fields"][field]["file"].get<std::string>();
  }

  // Runs `program args` in in/ once as `../outside/NAME` and once as the absolute path, with the
  // input written by `write(named)`; each must fail naming `key`, without opening `sentinel`;
  // then with --allow-outside-paths the sentinel is opened (glTF: only the relative path; tinygltf
  // reads a URI relative to the file's folder always, so an absolute one is not found even then).
  void expectContained(const char* program, const std::vector<std::string>& args, const std::string& key,
                       const fs::path& sentinel, const std::function<void(const std::string&)>& write,
                       bool absolute_followed = true) {
    const std::string relative = "../outside/" + fs::relative(sentinel, outside()).string();
    for (const std::string& named : {relative, sentinel.string()}) {
      write(named);
      {
        OpenWatch watch(sentinel);
        ProgramResult r = runProgram(program, args, in());
        EXPECT_EQ(r.exit_code, 2) << named << ": " << r.output;
        EXPECT_NE(r.output.find(key + ": '" + named + "' is outside the folder"), std::string::npos)
            << key << ": " << r.output;
        EXPECT_FALSE(watch.opened()) << key << " = " << named << ": the outside file was opened";
      }
      if (named == sentinel.string() && !absolute_followed) continue;
      std::vector<std::string> allowed = args;
      allowed.push_back("--allow-outside-paths");
      OpenWatch watch(sentinel);
      ProgramResult r = runProgram(program, allowed, in());
      EXPECT_TRUE(watch.opened()) << key << " = " << named << " with --allow-outside-paths: " << r.output;
    }
  }

  TempDir dir_{"eikonal-paths-cli"};
};

const std::vector<std::string> kRender = {"SCENE.json", "--render", "out.png", "--size", "8x8"};

TEST_F(PathsCli, SceneVolume) {
  expectContained(VIEWER_EXE, kRender, "objects[0].volume", outside() / "ball.vol.json", [&](const std::string& named) {
    writeFile(in() / "SCENE.json", json({{"objects", {{{"volume", named}}}}}).dump());
  });
}

TEST_F(PathsCli, SceneEnvironment) {
  Image sky{8, 4, 4, std::vector<float>(8 * 4 * 4, 0.5f)};
  writeImage(outside() / "sky.exr", sky);
  expectContained(VIEWER_EXE, kRender, "environment.file", outside() / "sky.exr", [&](const std::string& named) {
    writeFile(in() / "SCENE.json",
              json({{"environment", {{"file", named}}}, {"objects", {{{"volume", "ball.vol.json"}}}}}).dump());
  });
}

TEST_F(PathsCli, ManifestField) {
  const json original = manifest(in());
  expectContained(VIEWER_EXE, {"ball.vol.json", "--render", "out.png", "--size", "8x8"}, "fields.ior.file",
                  outsideField("ior"), [&](const std::string& named) {
                    json m = original;
                    m.erase("generation");  // the outside file is of another write
                    m["fields"]["ior"]["file"] = named;
                    writeFile(in() / "ball.vol.json", m.dump());
                  });
}

TEST_F(PathsCli, ManifestReceiver) {
  ProgramResult r = runProgram(LIGHTSIM_EXE,
                               {"ball.vol.json", "-o", "baked.vol.json", "--light", "directional:0,-1,0", "--receiver",
                                "0,-0.6,0:0,1,0", "--backend", "cpu", "--quiet"},
                               outside());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json baked = json::parse(readFile(outside() / "baked.vol.json"));
  const fs::path receiver = outside() / baked["receivers"][0]["file"].get<std::string>();
  // The baked volume's fields copied in, its receiver left outside.
  json m = baked;
  m.erase("generation");
  for (auto& [name, spec] : m["fields"].items()) fs::copy_file(outside() / spec["file"].get<std::string>(), in() / spec["file"].get<std::string>());
  expectContained(VIEWER_EXE, {"baked.vol.json", "--render", "out.png", "--size", "8x8"}, "receivers[0].file", receiver,
                  [&](const std::string& named) {
                    m["receivers"][0]["file"] = named;
                    writeFile(in() / "baked.vol.json", m.dump());
                  });
}

TEST_F(PathsCli, NrrdDataFile) {
  ProgramResult r = runProgram(VOXELIZE_EXE,
                               {"procedural:sphere,r=0.5,ior=1.5", "-o", "d.vol.json", "--res", "8", "--detached",
                                "--quiet"},
                               in());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json m = json::parse(readFile(in() / "d.vol.json"));
  // The distances' file: a headless render reads them in every sharp volume (it leaves n unread in
  // one of constant-n materials, checking its header only).
  const fs::path header = in() / m["fields"]["interfaces"]["file"].get<std::string>();
  const std::string text = readFile(header);
  const std::size_t at = text.find("data file: ");
  ASSERT_NE(at, std::string::npos) << text;
  const std::string data_name = text.substr(at + 11, text.find('\n', at) - at - 11);
  fs::rename(in() / data_name, outside() / data_name);
  expectContained(VIEWER_EXE, {"d.vol.json", "--render", "out.png", "--size", "8x8"}, "data file",
                  outside() / data_name, [&](const std::string& named) {
                    writeFile(header, text.substr(0, at) + "data file: " + named + "\n");
                  });
}

// A tetrahedron whose buffer is the file `buffer_uri`, with an optional image URI.
std::string tetrahedronGltf(const std::string& buffer_uri, const std::string& image_uri = "") {
  json j = {{"asset", {{"version", "2.0"}}},
            {"scene", 0},
            {"scenes", {{{"nodes", {0}}}}},
            {"nodes", {{{"mesh", 0}}}},
            {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
            {"buffers", {{{"byteLength", 60}, {"uri", buffer_uri}}}},
            {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 48}},
                             {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 12}}}},
            {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"},
                            {"min", {0, 0, 0}}, {"max", {1, 1, 1}}},
                           {{"bufferView", 1}, {"componentType", 5121}, {"count", 12}, {"type", "SCALAR"}}}}};
  if (!image_uri.empty()) j["images"] = {{{"uri", image_uri}}};
  return j.dump();
}

void writeTetrahedronBuffer(const fs::path& path) {
  const float p[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  const unsigned char idx[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  writeFile(path, std::string(reinterpret_cast<const char*>(p), sizeof p) +
                      std::string(reinterpret_cast<const char*>(idx), sizeof idx));
}

const std::vector<std::string> kVoxelizeGltf = {"t.gltf", "-o", "t.vol.json", "--res", "8", "--quiet"};

TEST_F(PathsCli, GltfBufferUri) {
  writeTetrahedronBuffer(outside() / "t.bin");
  expectContained(VOXELIZE_EXE, kVoxelizeGltf, "buffers[0].uri", outside() / "t.bin",
                  [&](const std::string& named) { writeFile(in() / "t.gltf", tetrahedronGltf(named)); }, false);
}

TEST_F(PathsCli, GltfImageUri) {
  writeTetrahedronBuffer(in() / "t.bin");
  writeFile(outside() / "texture.png", "not decoded, but opened by tinygltf if allowed");
  expectContained(VOXELIZE_EXE, kVoxelizeGltf, "images[0].uri", outside() / "texture.png",
                  [&](const std::string& named) { writeFile(in() / "t.gltf", tetrahedronGltf("t.bin", named)); },
                  false);
}

}  // namespace
}  // namespace eik::test
