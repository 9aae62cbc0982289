// Atomic file output (docs/volume-format.md: "Writing is atomic ... an interrupted run never leaves a
// half-written volume behind"). Every file is first written under a hidden temporary name in its
// target's directory (`.NAME.tmp-<pid>-<random>`), then renamed into place; rename(2) within one
// directory replaces the target in one step, so readers see the old file or the new, never a part.
// SIGINT and SIGTERM remove the temporaries (core/interrupt.h); those a SIGKILL leaves are removed
// by the next write of the same target.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace eik {

// A group of files written together: stage() each one, write it, then commit() renames all of them
// into place in the order they were staged (stage the file that refers to the others, e.g. the
// manifest, last). If the set is destroyed without commit() (an exception, an early return), every
// temporary file is removed and no target is touched.
class AtomicFileSet {
 public:
  AtomicFileSet() = default;
  ~AtomicFileSet();
  AtomicFileSet(const AtomicFileSet&) = delete;
  AtomicFileSet& operator=(const AtomicFileSet&) = delete;
  AtomicFileSet(AtomicFileSet&& other) noexcept;
  AtomicFileSet& operator=(AtomicFileSet&& other) noexcept;

  // Registers `target` and returns the temporary path to write its content to (not yet created).
  // Throws InputError when the target's directory does not exist, RuntimeError when the target is
  // already staged in this set or has been committed.
  std::filesystem::path stage(const std::filesystem::path& target);

  // stage(target) and write `bytes` to the temporary file. Throws RuntimeError naming the target
  // on any I/O failure (directory not writable, disk full).
  void write(const std::filesystem::path& target, std::string_view bytes);

  // Renames every staged file into place, in staging order. Throws RuntimeError if a rename fails
  // (the remaining temporaries are then removed). Committing an empty set does nothing.
  void commit();

  // Removes every temporary file now; the set is empty afterwards. Never throws.
  void discard() noexcept;

  bool committed() const { return committed_; }
  // The targets staged and not yet committed, in order.
  std::vector<std::filesystem::path> targets() const;

 private:
  struct Entry {
    std::filesystem::path target;
    std::filesystem::path temporary;
    int slot = -1;  // in the table a SIGINT/SIGTERM handler cleans (core/interrupt.h)
  };
  std::vector<Entry> entries_;
  bool committed_ = false;
};

// Writes one file atomically: `bytes` go to a temporary beside `path`, which is then renamed onto
// `path`. For PNG/JSON/EXR writers and the like. Throws like AtomicFileSet::write/commit.
void writeFileAtomic(const std::filesystem::path& path, std::string_view bytes);

// The temporary name used for `target`: DIR/.NAME.tmp-<pid>-<random>.
std::filesystem::path temporaryPathFor(const std::filesystem::path& target);

// Removes the temporaries of `target` (.NAME.tmp-<pid>-…) that processes no longer alive left
// behind (killed by SIGKILL, or a crash). stage() calls it. Never throws.
void removeStaleTemporaries(const std::filesystem::path& target) noexcept;
// The same for every target in `dir` whose file name `of_target` accepts.
void removeStaleTemporaries(const std::filesystem::path& dir,
                            const std::function<bool(const std::string&)>& of_target) noexcept;

}  // namespace eik
