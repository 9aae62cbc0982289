// The programs' allocator (core/allocator.cpp): jemalloc, with the options that file compiles in.
#include <cstdlib>
#include <vector>

#include <gtest/gtest.h>

#if EIKONAL_JEMALLOC
#include <jemalloc/jemalloc.h>
#endif

namespace eik {
namespace {

#if EIKONAL_JEMALLOC
// The test programs link core/allocator.cpp as the programs do (eikonal_use_allocator). If its
// malloc_conf were not the symbol jemalloc reads (a C++ name, a copy in a library), jemalloc would
// run with its defaults, opt.thp "default": no huge pages, the fault counts of glibc's malloc.
TEST(Allocator, JemallocRunsWithHugePagesAsked) {
  if (std::getenv("MALLOC_CONF") != nullptr) GTEST_SKIP() << "MALLOC_CONF is set: the environment chose the options";
  const char* thp = nullptr;
  std::size_t size = sizeof thp;
  ASSERT_EQ(mallctl("opt.thp", &thp, &size, nullptr, 0), 0) << "jemalloc does not answer: not the allocator in use";
  EXPECT_STREQ(thp, "always");
  const char* metadata_thp = nullptr;
  size = sizeof metadata_thp;
  ASSERT_EQ(mallctl("opt.metadata_thp", &metadata_thp, &size, nullptr, 0), 0);
  EXPECT_STREQ(metadata_thp, "always");
  // Freed memory stays for reuse (re-bakes fault nothing in afresh).
  for (const char* option : {"opt.dirty_decay_ms", "opt.muzzy_decay_ms"}) {
    ssize_t decay = 0;
    size = sizeof decay;
    ASSERT_EQ(mallctl(option, &decay, &size, nullptr, 0), 0) << option;
    EXPECT_EQ(decay, -1) << option;
  }
}

// operator new and malloc both go through it: a large vector's block is one jemalloc knows (its
// usable size is jemalloc's size class, at least what was asked).
TEST(Allocator, NewAndMallocAreJemallocs) {
  std::vector<float> block(3u << 20);
  const std::size_t usable = malloc_usable_size(block.data());
  EXPECT_GE(usable, block.size() * sizeof(float));
  void* p = std::malloc(1000);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(sallocx(p, 0), malloc_usable_size(p));  // sallocx is jemalloc's own
  std::free(p);
}
#else
TEST(Allocator, JemallocRunsWithHugePagesAsked) { GTEST_SKIP() << "built without jemalloc (EIKONAL_JEMALLOC off)"; }
#endif

}  // namespace
}  // namespace eik
