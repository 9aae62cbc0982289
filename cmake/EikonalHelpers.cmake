# Warnings for our own code only (never for generated or third-party sources).
# -Wno-restrict: GCC 12 reports a false -Wrestrict inside libstdc++'s std::string operator+ at -O2
# and above (GCC bug 105329); it fires in any file that concatenates strings.
function(eikonal_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    target_compile_options(${target} PRIVATE -Wno-restrict)
  endif()
endfunction()

# One test executable per folder: every NAME_test.cpp in DIR, linked against LIBS.
function(eikonal_add_tests name dir)
  if(NOT EIKONAL_BUILD_TESTS)
    return()
  endif()
  file(GLOB test_sources CONFIGURE_DEPENDS ${dir}/*_test.cpp)
  if(NOT test_sources)
    return()
  endif()
  add_executable(${name} ${test_sources})
  target_link_libraries(${name} PRIVATE ${ARGN} GTest::gtest GTest::gtest_main)
  eikonal_warnings(${name})
  target_compile_definitions(${name} PRIVATE EIKONAL_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
                                              EIKONAL_BINARY_DIR="${PROJECT_BINARY_DIR}")
  gtest_discover_tests(${name} WORKING_DIRECTORY ${PROJECT_BINARY_DIR} DISCOVERY_TIMEOUT 60
                       PROPERTIES ENVIRONMENT "EIKONAL_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
endfunction()
