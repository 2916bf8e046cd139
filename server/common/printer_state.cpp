#include "server/common/printer_state.hpp"

#include <array>
#include <utility>

#include "core/common/name_table.hpp"

namespace salient::server {
namespace {

constexpr core::NameTable<PrinterState, 8> printer_names{{
    {PrinterState::disconnected, "disconnected"},
    {PrinterState::connecting, "connecting"},
    {PrinterState::operational, "operational"},
    {PrinterState::printing, "printing"},
    {PrinterState::paused, "paused"},
    {PrinterState::cancelling, "cancelling"},
    {PrinterState::finishing, "finishing"},
    {PrinterState::error, "error"},
}};

constexpr core::NameTable<PrintState, 6> print_names{{
    {PrintState::printing, "printing"},
    {PrintState::paused, "paused"},
    {PrintState::finished, "finished"},
    {PrintState::failed, "failed"},
    {PrintState::cancelled, "cancelled"},
    {PrintState::interrupted, "interrupted"},
}};

}  // namespace

std::string_view to_string(PrinterState s) {
  return core::name_in(printer_names, s, "error");
}

std::string_view to_string(PrintState s) {
  return core::name_in(print_names, s, "failed");
}

std::optional<PrintState> print_state_from(std::string_view s) {
  return core::value_in(print_names, s);
}

}  // namespace salient::server
