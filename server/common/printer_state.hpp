// PrinterState and PrintState: what a printer is doing, and what became of one print. Each has
// one name table (printer_state.cpp); the names are used only where text is made or read (API
// JSON, database rows).
//
// Printer states: disconnected → connecting → operational ⇄ printing ⇄ paused; printing →
// finishing (every command of the file is confirmed; the print is being recorded) → operational;
// printing or paused → cancelling → operational; error after a failure (link lost, firmware
// halted, emergency stop, a connect that failed) until the next connect. OctoPrint's clients see
// finishing and cancelling as flags, and FDM Monster ends a print only on them.
//
// Print states: printing ⇄ paused → finished | cancelled | failed | interrupted (the daemon
// stopped, or the link dropped: resumable from its last acknowledged command).
#pragma once

#include <optional>
#include <string_view>

namespace salient::server {

enum class PrinterState {
  disconnected,
  connecting,
  operational,
  printing,
  paused,
  cancelling,
  finishing,
  error
};

std::string_view to_string(PrinterState s);
// A print is running on the link (streaming, paused, being cancelled, or finishing).
inline bool busy_printing(PrinterState s) {
  return s == PrinterState::printing || s == PrinterState::paused || s == PrinterState::cancelling ||
         s == PrinterState::finishing;
}
// The link is up (disconnected, connecting and error are not).
inline bool connected(PrinterState s) {
  return s != PrinterState::disconnected && s != PrinterState::connecting && s != PrinterState::error;
}

enum class PrintState { printing, paused, finished, failed, cancelled, interrupted };

std::string_view to_string(PrintState s);
std::optional<PrintState> print_state_from(std::string_view s);
// Still running on a printer (not ended).
inline bool running(PrintState s) {
  return s == PrintState::printing || s == PrintState::paused;
}

}  // namespace salient::server
