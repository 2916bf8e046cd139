#include "server/common/json_text.hpp"

#include <nlohmann/json.hpp>
#include <stdexcept>

namespace salient::server {

std::string json_text(const nlohmann::json& j, int indent) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

nlohmann::json parse_json_text(std::string_view text, std::size_t max_depth) {
  bool too_deep = false;
  const nlohmann::json::parser_callback_t check = [&](int depth, nlohmann::json::parse_event_t,
                                                      nlohmann::json&) {
    // Called as each value starts, with how many containers hold it.
    if (static_cast<std::size_t>(depth) > max_depth) {
      too_deep = true;
      throw std::invalid_argument("too deep");
    }
    return true;
  };
  try {
    return nlohmann::json::parse(text, check);
  } catch (const std::exception& e) {
    if (too_deep) throw std::invalid_argument("nested deeper than " + std::to_string(max_depth));
    // nlohmann's message quotes the bytes it last read; json_text() makes them safe later.
    throw std::invalid_argument(std::string("not valid JSON: ") + e.what());
  }
}

}  // namespace salient::server
