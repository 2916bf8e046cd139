// PrinterKind and PrinterProtocol: how a configured printer is reached, and the protocol it
// speaks. Each has one name table (printer_kind.cpp), read from the config and written in API JSON.
#pragma once

#include <optional>
#include <string_view>

namespace salient::server {

// sim: salient-sim started on a pseudo-terminal; serial: a USB serial device; tcp: a
// ser2net-style bridge at host:port.
enum class PrinterKind { sim, serial, tcp };

std::string_view to_string(PrinterKind k);
std::optional<PrinterKind> printer_kind_from(std::string_view s);

// marlin: numbered G-code lines; s3g: MakerBot's binary packets (Sailfish), the G-code translated
// to x3g on the way.
enum class PrinterProtocol { marlin, s3g };

std::string_view to_string(PrinterProtocol p);
std::optional<PrinterProtocol> printer_protocol_from(std::string_view s);

}  // namespace salient::server
