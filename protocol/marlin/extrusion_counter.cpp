#include "protocol/marlin/extrusion_counter.hpp"

#include <algorithm>
#include <string_view>

#include "protocol/marlin/line_codec.hpp"

namespace salient::protocol::marlin {

void ExtrusionCounter::step(const std::string& command, bool count) {
  const std::string_view code = std::string_view(command).substr(0, command.find(' '));
  if (code == "G90") {
    relative_ = false;
  } else if (code == "G91") {
    relative_ = true;
  } else if (code == "M82") {
    relative_e_ = false;
  } else if (code == "M83") {
    relative_e_ = true;
  } else if (code == "G20") {
    inches_ = true;
  } else if (code == "G21") {
    inches_ = false;
  } else if (code == "G92") {
    if (auto e = word_value(command, 'E')) e_ = *e * (inches_ ? 25.4 : 1);
    if (auto z = word_value(command, 'Z')) z_ = *z * (inches_ ? 25.4 : 1);
  } else if (code == "G28") {
    const bool any = word_value(command, 'X') || word_value(command, 'Y') || word_value(command, 'Z');
    if (!any || word_value(command, 'Z')) z_ = 0;
  } else if (code == "G0" || code == "G1" || code == "G2" || code == "G3") {
    if (const auto z = word_value(command, 'Z')) {
      const double v = *z * (inches_ ? 25.4 : 1);
      z_ = relative_ ? z_.value_or(0) + v : v;
    }
    const auto e = word_value(command, 'E');
    if (!e) return;
    const double v = *e * (inches_ ? 25.4 : 1);
    const double to = relative_ || relative_e_ ? e_ + v : v;
    if (count) extruded_ += to - e_;
    e_ = to;
  }
}

double ExtrusionCounter::advance_to(std::size_t end) {
  const double before = extruded_;
  for (end = std::min(end, program_->size()); next_ < end; ++next_) step((*program_)[next_].text, true);
  return extruded_ - before;
}

void ExtrusionCounter::skip_to(std::size_t end) {
  for (end = std::min(end, program_->size()); next_ < end; ++next_) step((*program_)[next_].text, false);
}

}  // namespace salient::protocol::marlin
