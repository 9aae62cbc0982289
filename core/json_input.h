// Parsing JSON that comes from anywhere (volume manifests, SCENE.json, glTF): one entry point for
// every reader, so that a hostile document fails with a clear InputError (exit 2, naming the file
// and the key) before any recursive code sees it (docs/programs.md "Limits").
//  - Nesting deeper than maxJsonDepth() levels is refused while parsing: nlohmann's parser keeps
//    its own stack, but copying, printing and destroying a document recurse per level, and a key
//    nested 10⁵ deep overflowed the call stack there.
//  - A number beyond the range of double (1e999) names the key it belongs to, instead of escaping
//    as json::out_of_range.
//  - Syntax errors keep nlohmann's message (line and column) without its "[json.exception...]" tag.
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace eik {

// Default limit on the nesting depth of a JSON document (objects and arrays); real manifests,
// scenes and glTF files nest fewer than 20 levels. EIKONAL_MAX_JSON_DEPTH (1 … 100000) overrides it.
constexpr int kMaxJsonDepth = 256;
int maxJsonDepth();

// Parses `text`; InputError "SOURCE: FIELD: ..." on failure, FIELD being `syntax_field` for a
// syntax error or too deep a nesting and the last key read for a number out of range.
nlohmann::json parseJsonInput(std::string_view text, const std::string& source,
                              const std::string& syntax_field = "JSON");

}  // namespace eik
