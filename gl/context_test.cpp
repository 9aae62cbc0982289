// Tests of gl/context: back-end selection, and the same known pattern rendered and read back pixel
// by pixel through OSMesa, EGL surfaceless and a GLFW window (under Xvfb; see gl/CMakeLists.txt).
#include "gl/context.h"

#include <gtest/gtest.h>

#include <dlfcn.h>

#include <cstdio>
#include <cstdlib>

#include "gl/debug.h"
#include "core/testing.h"
#include "gl/test_util.h"

namespace eik::gl {
namespace {

using test_support::ScopedEnv;

void printInfo(const GlContext& context) {
  std::printf("[ context  ] %s\n", context.summary().c_str());
}

TEST(GlBackendTest, ParsesNamesAndEnvironment) {
  EXPECT_EQ(parseGlBackend("auto"), GlBackend::Auto);
  EXPECT_EQ(parseGlBackend("OSMesa"), GlBackend::OSMesa);
  EXPECT_EQ(parseGlBackend("egl"), GlBackend::EGL);
  EXPECT_EQ(parseGlBackend("window"), GlBackend::Window);
  EXPECT_EQ(glBackendName(GlBackend::EGL), "egl");
  try {
    parseGlBackend("vulkan", "--gl");
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--gl"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("vulkan"), std::string::npos) << e.what();
  }
  {
    ScopedEnv env("EIKONAL_GL", "egl");
    EXPECT_EQ(glBackendFromEnvironment(), GlBackend::EGL);
  }
  {
    ScopedEnv env("EIKONAL_GL", nullptr);
    EXPECT_EQ(glBackendFromEnvironment(GlBackend::OSMesa), GlBackend::OSMesa);
  }
  {
    ScopedEnv env("EIKONAL_GL", "nope");
    EXPECT_THROW(glBackendFromEnvironment(), InputError);
  }
}

TEST(GlInfoTest, TellsSoftwareRasterizersFromGpus) {
  GlInfo info;
  for (const char* renderer : {"llvmpipe (LLVM 15.0.6, 256 bits)", "softpipe", "Mesa X11 swrast", "SwiftShader Device"}) {
    info.renderer = renderer;
    EXPECT_TRUE(isSoftwareRenderer(info)) << renderer;
  }
  for (const char* renderer : {"NVIDIA H100 80GB HBM3/PCIe/SSE2", "AMD Radeon RX 7900 XTX (radeonsi, navi31)",
                               "Mesa Intel(R) UHD Graphics 630 (CFL GT2)", ""}) {
    info.renderer = renderer;
    EXPECT_FALSE(isSoftwareRenderer(info)) << renderer;
  }
}

TEST(OSMesaContext, RendersPatternPixelExact) {
  GlContext context(ContextOptions{.backend = GlBackend::OSMesa});
  printInfo(context);
  EXPECT_EQ(context.backend(), GlBackend::OSMesa);
  EXPECT_EQ(GlContext::current(), &context);
  const GlInfo& info = context.info();
  EXPECT_GE(info.major * 10 + info.minor, 33) << info.version;
  EXPECT_TRUE(info.coreProfile);
  EXPECT_FALSE(info.renderer.empty());
  EXPECT_GE(info.max3DTextureSize, 256);
  EXPECT_GE(info.maxColorAttachments, 4);
  EXPECT_FALSE(context.isWindow());
  EXPECT_EQ(context.window(), nullptr);
  test::renderAndCheckPattern(96, 64);
}

// libOSMesa (and the LLVM it loads) is opened only when an OSMesa context is made: the CPU twin and
// EGL never load it (context_osmesa.cpp). ctest runs each test in a process of its own, so nothing
// has made a context before this test starts.
TEST(OSMesaContext, LibraryIsLoadedOnlyWhenAnOSMesaContextIsMade) {
  auto loaded = [] {
    void* handle = dlopen("libOSMesa.so.8", RTLD_NOW | RTLD_NOLOAD);
    if (handle) dlclose(handle);  // drops only the reference RTLD_NOLOAD took
    return handle != nullptr;
  };
  if (::testing::UnitTest::GetInstance()->test_to_run_count() != 1) {
    GTEST_SKIP() << "needs a process of its own (ctest runs it so): other tests make OSMesa contexts";
  }
  EXPECT_FALSE(loaded()) << "libOSMesa.so.8 was loaded before any context was made (linked, not opened)";
  GlContext context(ContextOptions{.backend = GlBackend::OSMesa});
  EXPECT_TRUE(loaded());
}

TEST(EglContext, RendersPatternPixelExact) {
  std::unique_ptr<GlContext> context;
  try {
    context = std::make_unique<GlContext>(ContextOptions{.backend = GlBackend::EGL});
  } catch (const RuntimeError& e) {
    GTEST_SKIP() << "EGL cannot create a context on this machine: " << e.what();
  }
  printInfo(*context);
  EXPECT_EQ(context->backend(), GlBackend::EGL);
  EXPECT_TRUE(context->info().coreProfile);
  EXPECT_GE(context->info().major * 10 + context->info().minor, 33);
  test::renderAndCheckPattern(64, 48);
}

TEST(EglContext, EachDisplayKindThatExistsRenders) {
  int rendered = 0;
  for (const char* platform : {"device", "surfaceless", "default"}) {
    ScopedEnv env("EIKONAL_EGL_PLATFORM", platform);
    std::unique_ptr<GlContext> context;
    try {
      context = std::make_unique<GlContext>(ContextOptions{.backend = GlBackend::EGL});
    } catch (const RuntimeError& e) {
      std::printf("[ egl      ] %s: unavailable: %s\n", platform, e.what());
      continue;
    }
    std::printf("[ egl      ] %s: %s\n", platform, context->summary().c_str());
    EXPECT_NE(context->info().platform.find(platform), std::string::npos) << context->info().platform;
    test::renderAndCheckPattern(24, 16);
    ++rendered;
  }
  if (rendered == 0) GTEST_SKIP() << "no EGL display gives a context on this machine";
}

TEST(GlContextTest, AutoIsHeadlessOSMesaFirst) {
  ScopedEnv env("EIKONAL_GL", nullptr);
  GlContext context;
  EXPECT_EQ(context.backend(), GlBackend::OSMesa);
}

TEST(GlContextTest, EnvironmentPicksTheBackEnd) {
  ScopedEnv env("EIKONAL_GL", "egl");
  std::unique_ptr<GlContext> context;
  try {
    context = std::make_unique<GlContext>();
  } catch (const RuntimeError& e) {
    GTEST_SKIP() << "EGL unavailable: " << e.what();
  }
  EXPECT_EQ(context->backend(), GlBackend::EGL);
}

TEST(GlContextTest, TwoBackEndsInOneProcess) {
  // glad's pointers are global: switching between an OSMesa and an EGL context must reload them.
  GlContext osmesa(ContextOptions{.backend = GlBackend::OSMesa});
  std::unique_ptr<GlContext> egl;
  try {
    egl = std::make_unique<GlContext>(ContextOptions{.backend = GlBackend::EGL});
  } catch (const RuntimeError& e) {
    GTEST_SKIP() << "EGL unavailable: " << e.what();
  }
  for (int round = 0; round < 2; ++round) {
    osmesa.makeCurrent();
    test::renderAndCheckPattern(16, 16);
    egl->makeCurrent();
    test::renderAndCheckPattern(16, 16);
  }
}

TEST(GlContextTest, DebugChecksTurnGlErrorsIntoExceptions) {
  GlContext context(ContextOptions{.backend = glBackendFromEnvironment(GlBackend::OSMesa), .debug = true});
  EXPECT_TRUE(context.debug());
  EXPECT_TRUE(errorChecksEnabled());
  EXPECT_TRUE(context.info().debugOutput) << "Mesa offers KHR_debug";
  glBindTexture(GL_TEXTURE_2D, 987654u);  // never generated: GL_INVALID_OPERATION in core
  try {
    checkErrors("the test");
    FAIL() << "no exception";
  } catch (const RuntimeError& e) {
    std::string message = e.what();
    EXPECT_NE(message.find("the test"), std::string::npos) << message;
    EXPECT_NE(message.find("GL_INVALID_OPERATION"), std::string::npos) << message;
  }
  checkErrors("clean");  // the error was consumed
}

TEST(GlContextTest, NoChecksWithoutDebug) {
  GlContext context(ContextOptions{.backend = glBackendFromEnvironment(GlBackend::OSMesa), .debug = false});
  EXPECT_FALSE(errorChecksEnabled());
  glBindTexture(GL_TEXTURE_2D, 987654u);
  EXPECT_NO_THROW(checkErrors("unchecked"));
  EXPECT_THROW(checkErrorsAlways("always"), RuntimeError);
}

TEST(GlfwWindow, RendersPatternAndDefaultFramebuffer) {
  const bool required = std::getenv("EIKONAL_REQUIRE_DISPLAY") != nullptr;
  if (!displayAvailable()) {
    if (required) FAIL() << "EIKONAL_REQUIRE_DISPLAY is set but there is no DISPLAY";
    GTEST_SKIP() << "no DISPLAY (ctest runs this test under xvfb-run as gl_tests.GlfwWindowUnderXvfb)";
  }
  std::unique_ptr<GlContext> context;
  try {
    context = std::make_unique<GlContext>(
        ContextOptions{.backend = GlBackend::Window, .size = {64, 48}, .title = "Eikonal gl test", .visible = true});
  } catch (const RuntimeError& e) {
    if (required) FAIL() << e.what();
    GTEST_SKIP() << e.what();
  }
  printInfo(*context);
  ASSERT_TRUE(context->isWindow());
  ASSERT_NE(context->window(), nullptr);
  EXPECT_TRUE(context->info().coreProfile);
  EXPECT_FALSE(context->shouldClose());
  GlContext::pollEvents();

  test::renderAndCheckPattern(64, 48);  // into our own RGBA32F framebuffer

  // And into the window's default framebuffer (8 bits a channel): tolerance half a step.
  glm::ivec2 size = context->framebufferSize();
  ASSERT_GT(size.x, 0);
  ASSERT_GT(size.y, 0);
  ShaderLibrary library;
  Program program = library.program("common/fullscreen.vert", "test/pattern.frag", {{"MODE", "2"}});
  FullscreenTriangle triangle;
  Framebuffer::bindDefault(size);
  glClearColor(1, 0, 1, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  program.use();
  program.set("uSize", glm::vec2(size));
  triangle.draw();
  std::vector<float> pixels = readDefaultFramebufferRGBA(size);
  EXPECT_EQ(test::countPatternMismatches(pixels, size.x, size.y, 0.5f / 255.0f + 1e-6f), 0);
  context->swapBuffers();
  GlContext::pollEvents();
}

}  // namespace
}  // namespace eik::gl
