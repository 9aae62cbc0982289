// The programs' memory allocator: jemalloc (libjemalloc-dev) with transparent huge pages.
//
// A bake or a scene's load touches a few hundred MiB once (the fields, the patch lists, the receiver's
// sums). With glibc's malloc each fresh 4 KiB page costs a page fault, and on a virtual machine a
// fault costs microseconds: on the 2-core project box the 128³ bake took 133 000 faults and a third of
// its time in the kernel. jemalloc asks the kernel for 2 MiB pages on all its memory (opt.thp
// "always", madvise(MADV_HUGEPAGE); the system's setting "madvise" honours it), 512 times fewer faults:
// BENCHMARKS.md "Memory in huge pages". The same allocations and the same results, only faster.
// Freed memory is kept for reuse, never handed back to the kernel (dirty_decay_ms and muzzy_decay_ms
// -1): a process that bakes again and again (the window's re-bakes, `lightsim --bench`) would
// otherwise fault its patch lists in afresh each time (the 128³ sphere: 4 600 faults a bake, 460
// kept; the 64³ bake 0.175 → 0.162 s). A process keeps its peak memory until it exits.
// One arena (narenas:1) for all threads: memory one thread frees (a field a worker read, the
// simulator's copy made, then released) is reused by another thread's later allocations instead of
// staying in the first thread's arena while the other faults in fresh pages (the 128³ bake command's
// peak 137 → 129 MB, the render's 213 → 208 MB; each thread keeps its cache of small blocks, and two
// threads hardly contend for the arena's lock).
//
// This file is linked into the three programs and the test programs (cmake/EikonalHelpers.cmake,
// eikonal_use_allocator), never into the libraries, and not at all in a sanitizer or fuzzing build,
// where the sanitizers' own allocator must see every allocation. The environment's MALLOC_CONF is read
// after this and overrides it (MALLOC_CONF=thp:default turns the huge pages off).
#include <jemalloc/jemalloc.h>

extern "C" {
// jemalloc's compiled-in options (its documented interface: the application defines this symbol).
const char* malloc_conf = "thp:always,metadata_thp:always,dirty_decay_ms:-1,muzzy_decay_ms:-1,narenas:1";
}
