#include "server/common/printer_state.hpp"

#include <array>
#include <utility>

namespace salient::server {
namespace {

constexpr std::array<std::pair<PrinterState, std::string_view>, 7> printer_names{{
    {PrinterState::disconnected, "disconnected"},
    {PrinterState::connecting, "connecting"},
    {PrinterState::operational, "operational"},
    {PrinterState::printing, "printing"},
    {PrinterState::paused, "paused"},
    {PrinterState::cancelling, "cancelling"},
    {PrinterState::error, "error"},
}};

constexpr std::array<std::pair<PrintState, std::string_view>, 6> print_names{{
    {PrintState::printing, "printing"},
    {PrintState::paused, "paused"},
    {PrintState::finished, "finished"},
    {PrintState::failed, "failed"},
    {PrintState::cancelled, "cancelled"},
    {PrintState::interrupted, "interrupted"},
}};

}  // namespace

std::string_view to_string(PrinterState s) {
  for (const auto& [state, name] : printer_names)
    if (state == s) return name;
  return "error";
}

std::string_view to_string(PrintState s) {
  for (const auto& [state, name] : print_names)
    if (state == s) return name;
  return "failed";
}

std::optional<PrintState> print_state_from(std::string_view s) {
  for (const auto& [state, name] : print_names)
    if (name == s) return state;
  return std::nullopt;
}

}  // namespace salient::server
