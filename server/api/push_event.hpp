// PushEvent: the OctoPrint events (`{"event": {"type", "payload"}}` on the push socket) that a
// change of the printer's state means: PrinterStateChanged always; PrintStarted, PrintPaused,
// PrintResumed, PrintDone, PrintCancelled, PrintFailed for the print; Connected, Disconnected and
// Error for the link. Payloads as OctoPrint's documentation lists them (docs/events/index.rst).
#pragma once

#include <string>
#include <vector>

#include "server/printers/printer_status.hpp"

namespace salient::server {

struct PushEvent {
  std::string type;
  std::string payload;  // JSON text
};

// The events of the change from `before` to `after` (two successive states of one printer), in
// the order OctoPrint fires them.
std::vector<PushEvent> push_events(const PrinterStatus& before, const PrinterStatus& after);

}  // namespace salient::server
