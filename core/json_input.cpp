// Parsing untrusted JSON (see json_input.h).
#include "core/json_input.h"

#include <cstdlib>

#include "core/error.h"

namespace eik {

namespace {

// nlohmann's message without its "[json.exception.parse_error.101] " tag.
std::string untagged(const std::string& what) {
  const std::size_t end = what.find("] ");
  return what.rfind("[json.exception", 0) == 0 && end != std::string::npos ? what.substr(end + 2) : what;
}

}  // namespace

int maxJsonDepth() {
  if (const char* text = std::getenv("EIKONAL_MAX_JSON_DEPTH")) {
    char* end = nullptr;
    const long value = std::strtol(text, &end, 10);
    if (end != text && *end == '\0' && value >= 1 && value <= 100000) return static_cast<int>(value);
  }
  return kMaxJsonDepth;
}

nlohmann::json parseJsonInput(std::string_view text, const std::string& source, const std::string& syntax_field) {
  using json = nlohmann::json;
  const int limit = maxJsonDepth();
  std::string last_key;
  // Called by the parser for every event with the depth of the element; refusing the start of an
  // object or array past the limit stops the parse before the document gets deeper.
  const json::parser_callback_t check = [&](int depth, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::key && parsed.is_string()) last_key = parsed.get<std::string>();
    if ((event == json::parse_event_t::object_start || event == json::parse_event_t::array_start) && depth >= limit)
      throw InputError(source, syntax_field,
                       "nested deeper than " + std::to_string(limit) +
                           " levels (the limit for JSON input; EIKONAL_MAX_JSON_DEPTH raises it)");
    return true;
  };
  try {
    return json::parse(text.begin(), text.end(), check);
  } catch (const json::parse_error& e) {
    throw InputError(source, syntax_field, untagged(e.what()));
  } catch (const json::out_of_range& e) {
    throw InputError(source, last_key.empty() ? syntax_field : last_key, "number out of range (" + untagged(e.what()) + ")");
  } catch (const json::exception& e) {
    throw InputError(source, syntax_field, untagged(e.what()));
  }
}

}  // namespace eik
