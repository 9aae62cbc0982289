# Warnings for our own code only (never for generated or third-party sources).
# -Wno-restrict: GCC 12 reports a false -Wrestrict inside libstdc++'s std::string operator+ at -O2
# and above (GCC bug 105329); it fires in any file that concatenates strings.
function(eikonal_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    target_compile_options(${target} PRIVATE -Wno-restrict)
  endif()
endfunction()

# eikonal_use_allocator(TARGET): an executable gets the programs' allocator (core/allocator.cpp:
# jemalloc, huge pages on) unless EIKONAL_JEMALLOC is off (sanitizer and fuzz builds).
function(eikonal_use_allocator target)
  if(EIKONAL_JEMALLOC)
    target_sources(${target} PRIVATE ${PROJECT_SOURCE_DIR}/core/allocator.cpp)
    target_link_libraries(${target} PRIVATE PkgConfig::JEMALLOC)
  endif()
endfunction()

# eikonal_add_tests(NAME SOURCES a_test.cpp ... [SUPPORT helper.cpp ...] LIBS lib ...): one gtest
# executable per folder, from the tests listed (x_test.cpp beside x.cpp) and any test-only support
# sources, which thereby stay out of the product libraries.
function(eikonal_add_tests name)
  if(NOT EIKONAL_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "" "SOURCES;SUPPORT;LIBS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES} ${ARG_SUPPORT})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest eikonal_test_main)
  eikonal_warnings(${name})
  eikonal_use_allocator(${name})
  target_compile_definitions(${name} PRIVATE EIKONAL_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
                                              EIKONAL_BINARY_DIR="${PROJECT_BINARY_DIR}")
  gtest_discover_tests(${name} WORKING_DIRECTORY ${PROJECT_BINARY_DIR} DISCOVERY_TIMEOUT 60
                       PROPERTIES ENVIRONMENT "EIKONAL_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
endfunction()

# eikonal_add_xvfb_test(NAME TARGET FILTER): runs the tests of the gtest binary TARGET matching
# FILTER on their own under a virtual X display (xvfb-run). In the plain (discovered) run such tests
# skip when DISPLAY is unset; here EIKONAL_REQUIRE_DISPLAY makes a skip a failure.
# RESOURCE_LOCK xvfb: xvfb-run -a's search for a free display number races under ctest -j.
function(eikonal_add_xvfb_test name target filter)
  if(NOT EIKONAL_BUILD_TESTS OR NOT TARGET ${target})
    return()
  endif()
  find_program(XVFB_RUN xvfb-run)
  if(NOT XVFB_RUN)
    message(STATUS "xvfb-run not found: ${filter} runs only where DISPLAY is set")
    return()
  endif()
  add_test(NAME ${name}
           COMMAND ${XVFB_RUN} -a -s "-screen 0 640x480x24" $<TARGET_FILE:${target}> --gtest_filter=${filter}
           WORKING_DIRECTORY ${PROJECT_BINARY_DIR})
  set_tests_properties(${name} PROPERTIES
    ENVIRONMENT "EIKONAL_REQUIRE_DISPLAY=1;EIKONAL_SOURCE_DIR=${PROJECT_SOURCE_DIR}"
    RESOURCE_LOCK xvfb TIMEOUT 120)
endfunction()
