// PrinterStatus: one printer at one moment, copied out under its lock. The API turns it into JSON
// (server/api/printer_json.cpp); OctoPrint's routes and /metrics read its fields.
#pragma once

#include <optional>
#include <string>

#include "server/common/printer_state.hpp"
#include "server/config/printer_kind.hpp"
#include "server/store/print_store.hpp"

namespace salient::server {

struct Temperature {
  std::optional<double> actual, target;  // °C; none until the printer reported one
};

struct PrinterStatus {
  std::string id;
  PrinterKind kind = PrinterKind::sim;
  PrinterProtocol protocol = PrinterProtocol::marlin;
  std::string profile;
  PrinterState state = PrinterState::disconnected;
  std::string error, firmware, device;  // empty: none
  Temperature hotend, bed;
  // The print under way: its record with the live state (printing or paused), confirmed and total.
  struct Running {
    PrintRecord record;
    double elapsed = 0;  // seconds since it started
    // The layer under way (1-based) of the file's layers, by its ";LAYER_CHANGE"/";LAYER:"
    // comments; 0 when the file marks none.
    std::size_t layer = 0, layers = 0;
    // Bytes of the file done (where the first unconfirmed command's line starts; the whole file
    // once all are confirmed) and the file's size: OctoPrint's progress.filepos counts bytes.
    std::size_t filepos = 0, file_bytes = 0;
    std::optional<double> z;  // the nozzle's height at the last confirmed command, by the file
    double fraction() const {
      return record.total > 0 ? double(record.confirmed) / double(record.total) : 0.0;
    }
    // Seconds left at the pace so far; none in the first 1 %, when the pace says little.
    std::optional<double> eta() const {
      const double f = fraction();
      return f > 0.01 ? std::optional<double>(elapsed * (1 - f) / f) : std::nullopt;
    }
  };
  std::optional<Running> print;
  std::optional<PrintRecord> last_print;
};

}  // namespace salient::server
