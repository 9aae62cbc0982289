// OBJ loading: face forms, relative indices, polygons, object/group/material splits, and broken
// files that must give an InputError naming the file, the line and the keyword.
#include "voxelize/obj_loader.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/error.h"
#include "core/testing.h"
#include "voxelize/mesh_scene.h"

namespace eik {
namespace {

class ObjLoader : public ::testing::Test {
 protected:
  std::filesystem::path write(const std::string& name, const std::string& text) {
    const auto path = dir_ / name;
    test_support::writeFile(path, text);
    return path;
  }
  void expectInputError(const std::string& text, std::initializer_list<const char*> parts) {
    const auto path = write("broken.obj", text);
    try {
      loadMeshFile(path);
      ADD_FAILURE() << "no error for:\n" << text;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind(path.string() + ": ", 0), 0u) << message;
      for (const char* part : parts) EXPECT_NE(message.find(part), std::string::npos) << message << " lacks " << part;
    }
  }

  test_support::TempDir dir_{"eikonal-obj"};
};

// A unit cube: 8 vertices, 6 quads.
const char* kCubeVertices =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";

TEST_F(ObjLoader, FaceFormsRelativeIndicesAndPolygons) {
  const std::string text = std::string("# a cube written four ways\r\n") + kCubeVertices +
                           "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n"
                           "f 1 4 3 2\n"                   // plain, quad (bottom, −z)
                           "f 5/1 6/2 7/3 8/1\n"           // v/vt (top, +z)
                           "f 1//1 2//1 6//1 5//1\r\n"     // v//vn (front, −y), CRLF
                           "f -5/1/1 -1/2/1 -2/3/1 -6/1/1\n"  // negative v/vt/vn (back, +y): 4 8 7 3
                           "f 1 5 \\\n 8 4\n"               // continued line (left, −x)
                           "f 2 3 7 6 # right, +x\n";
  const MeshScene scene = loadMeshFile(write("cube.obj", text));
  ASSERT_EQ(scene.meshes.size(), 1u);
  const TriangleMesh& cube = scene.meshes[0];
  EXPECT_EQ(cube.name, "cube");  // the file stem
  EXPECT_EQ(cube.triangleCount(), 12u);
  EXPECT_EQ(cube.positions.size(), 8u);
  EXPECT_TRUE(cube.isClosed());
  EXPECT_NEAR(cube.signedVolume(), 1.0, 1e-12);
  EXPECT_FALSE(cube.material.opaque);
  EXPECT_FLOAT_EQ(cube.material.ior, 1.5f);  // default glass
  EXPECT_TRUE(scene.lights.empty());
  EXPECT_TRUE(scene.cameras.empty());
}

TEST_F(ObjLoader, ObjectsGroupsAndMaterialsSplitMeshes) {
  const std::string text = std::string("mtllib scene.mtl\n") + kCubeVertices +
                           "o Table\nusemtl wood\nf 1 2 3\nf 1 3 4\n"
                           "usemtl metal\nf 5 6 7\n"
                           "o Glass\ng bowl\nf 5 7 8\n"
                           "o Table\nusemtl wood\nf 1 2 6\n"  // back to the first: appended to it
                           "l 1 2\n"
                           "s off\n";
  const MeshScene scene = loadMeshFile(write("scene.obj", text));
  ASSERT_EQ(scene.meshes.size(), 3u);
  EXPECT_EQ(scene.meshes[0].name, "Table (wood)");
  EXPECT_EQ(scene.meshes[0].material.name, "wood");
  EXPECT_EQ(scene.meshes[0].triangleCount(), 3u);
  EXPECT_EQ(scene.meshes[0].positions.size(), 5u);  // only the vertices it uses
  EXPECT_EQ(scene.meshes[1].name, "Table (metal)");
  EXPECT_EQ(scene.meshes[1].triangleCount(), 1u);
  EXPECT_EQ(scene.meshes[2].name, "Glass/bowl (metal)");  // usemtl holds across o and g
  EXPECT_EQ(scene.meshes[2].material.name, "metal");
  EXPECT_EQ(scene.meshes[2].positions[1], glm::dvec3(1, 1, 1));
  ASSERT_EQ(scene.warnings.size(), 1u);  // the 'l' element
  EXPECT_NE(scene.warnings[0].find("'l'"), std::string::npos) << scene.warnings[0];
}

TEST_F(ObjLoader, NonNumericValueIsAnInputError) {
  expectInputError("v 0 0 0\nv 1 0 0\nv 0 abc 0\nf 1 2 3\n", {"line 3: v", "'abc' is not a number"});
  expectInputError("v 0 0 0\nv 1 0 0\nv 0 1\nf 1 2 3\n", {"line 3: v", "needs 3 coordinates"});
  expectInputError("v 0 0 0\nv 1 0 0\nv 0 1 nan\nf 1 2 3\n", {"line 3: v", "finite"});
  expectInputError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", {"line 4: f", "'x' is not an index"});
  expectInputError("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 one\nf 1 2 3\n", {"line 4: vn"});
}

TEST_F(ObjLoader, IndexOutOfRangeIsAnInputError) {
  expectInputError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", {"line 4: f", "vertex index 4 is out of range"});
  expectInputError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", {"line 4: f", "index -4 is out of range"});
  expectInputError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", {"line 4: f", "index 0"});
  expectInputError("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n", {"line 5: f", "texture coordinate index 2"});
  expectInputError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", {"line 4: f", "at least 3 corners"});
  // A forward reference to a vertex defined later is fine.
  const MeshScene scene = loadMeshFile(write("forward.obj", "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"));
  EXPECT_EQ(scene.meshes[0].triangleCount(), 1u);
}

TEST_F(ObjLoader, EmptyMeshIsAnInputError) {
  expectInputError("", {"f", "empty mesh"});
  expectInputError("# only a comment\nv 0 0 0\nv 1 0 0\n", {"f", "empty mesh", "2 vertices but no faces"});
  try {
    loadMeshFile(dir_ / "missing.obj");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot be opened"), std::string::npos) << e.what();
  }
}

TEST_F(ObjLoader, TruncatedFilesNeverCrash) {
  const std::string text = std::string(kCubeVertices) + "f 1 4 3 2\nf 5/1 6/1 7/1 8/1\nvt 0.5 0.5\nf -1 -2 -3\n";
  for (std::size_t cut = 0; cut <= text.size(); cut += 3) {
    try {
      parseObj(text.substr(0, cut), "cut.obj");
    } catch (const InputError&) {
    }
  }
}

}  // namespace
}  // namespace eik
