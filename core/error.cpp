#include "core/error.h"

#include <cstdio>
#include <exception>
#include <new>

#include "core/interrupt.h"

namespace eik {

namespace {
// "SOURCE: FIELD: WHAT" (FIELD left out when empty). Appended piece by piece: GCC 12 warns
// (-Wrestrict, a false positive) on chains of std::string operator+ with literals.
std::string joinMessage(const std::string& source, const std::string& field, const std::string& what) {
  std::string message = source;
  if (!field.empty()) message.append(": ").append(field);
  message.append(": ").append(what);
  return message;
}
}  // namespace

InputError::InputError(const std::string& source, const std::string& field, const std::string& what)
    : std::runtime_error(joinMessage(source, field, what)) {}

int runMain(const char* program, int (*body)(int, char**), int argc, char** argv) {
  installInterruptHandlers(program);
  try {
    return body(argc, argv);
  } catch (const InputError& e) {
    std::fprintf(stderr, "%s: error: %s\n", program, e.what());
    return kExitBadInput;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "%s: error: out of memory\n", program);
    return kExitRuntime;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", program, e.what());
    return kExitRuntime;
  }
}

}  // namespace eik
