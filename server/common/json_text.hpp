// json_text: the one way the daemon turns JSON into text. Outside bytes (a path, a topic, a
// console line, a model's header) reach messages unchecked, and nlohmann's dump() throws on
// invalid UTF-8; here such bytes become U+FFFD instead, so no echo can abort a handler.
#pragma once

#include <cstddef>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>

namespace salient::server {

std::string json_text(const nlohmann::json& j, int indent = -1);

// Parses outside text. Depth is refused while parsing, at the first value nested deeper than
// `max_depth`, so that no deep tree is ever built (80,000 levels would overflow the stack of
// whatever walks it). Throws std::invalid_argument: "nested deeper than N" or "not valid JSON: …".
nlohmann::json parse_json_text(std::string_view text, std::size_t max_depth);

}  // namespace salient::server
