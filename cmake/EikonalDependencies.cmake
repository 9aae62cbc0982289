# All third-party dependencies come from Debian packages (scripts/setup.sh installs them).
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)
find_package(ZLIB REQUIRED)
find_package(glm REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(TinyGLTF REQUIRED)   # a compiled library on Debian: never define TINYGLTF_IMPLEMENTATION
find_package(glfw3 3.3 REQUIRED)
find_package(hwy 1.0 REQUIRED)     # Google Highway, header-only: the CPU twin's SIMD, dispatched at run time (lightsim/track_deposit_cpu.cpp)
pkg_check_modules(OSMESA REQUIRED IMPORTED_TARGET osmesa)
pkg_check_modules(EGL REQUIRED IMPORTED_TARGET egl)
# Dear ImGui 1.86 (libimgui-dev): libimgui.a holds the core and the back ends, imgui_impl_glfw and
# imgui_impl_opengl3 included (the latter loads GL itself from libGL.so.1); headers under imgui/.
pkg_check_modules(IMGUI REQUIRED IMPORTED_TARGET imgui>=1.86)
# Images (core/image_io): OpenEXR, libpng and stb_image (Radiance .hdr), each the format's own
# library; 20 shared libraries where OpenImageIO loaded 250 and took 0.18 s to start a program.
pkg_check_modules(OPENEXR REQUIRED IMPORTED_TARGET OpenEXR>=3)
pkg_check_modules(PNG REQUIRED IMPORTED_TARGET libpng16)
pkg_check_modules(STB REQUIRED IMPORTED_TARGET stb)
# NRRD gzip data (core/gzip_stream.cpp): libdeflate reads whole streams many times faster than
# zlib's streaming inflate; zlib stays for the parallel writer and for the reader's diagnoses.
pkg_check_modules(LIBDEFLATE REQUIRED IMPORTED_TARGET libdeflate)
# The programs' allocator (core/allocator.cpp): jemalloc with transparent huge pages. Not with the
# sanitizers or the fuzzers, whose own allocator must see every allocation.
if(EIKONAL_SANITIZE OR EIKONAL_FUZZ)
  set(EIKONAL_JEMALLOC OFF)
endif()
if(EIKONAL_JEMALLOC)
  pkg_check_modules(JEMALLOC REQUIRED IMPORTED_TARGET jemalloc)
endif()
if(EIKONAL_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(EIKONAL_BUILD_BENCHMARKS)
  find_package(benchmark QUIET)
endif()
find_program(GLAD_EXECUTABLE glad REQUIRED)   # python3-glad 2.x
