#include "server/config/printer_kind.hpp"

#include <array>
#include <utility>

namespace salient::server {
namespace {

constexpr std::array<std::pair<PrinterKind, std::string_view>, 3> kind_names{{
    {PrinterKind::sim, "sim"},
    {PrinterKind::serial, "serial"},
    {PrinterKind::tcp, "tcp"},
}};

constexpr std::array<std::pair<PrinterProtocol, std::string_view>, 1> protocol_names{{
    {PrinterProtocol::marlin, "marlin"},
}};

}  // namespace

std::string_view to_string(PrinterKind k) {
  for (const auto& [kind, name] : kind_names)
    if (kind == k) return name;
  return "serial";
}

std::optional<PrinterKind> printer_kind_from(std::string_view s) {
  for (const auto& [kind, name] : kind_names)
    if (name == s) return kind;
  return std::nullopt;
}

std::string_view to_string(PrinterProtocol p) {
  for (const auto& [protocol, name] : protocol_names)
    if (protocol == p) return name;
  return "marlin";
}

std::optional<PrinterProtocol> printer_protocol_from(std::string_view s) {
  for (const auto& [protocol, name] : protocol_names)
    if (name == s) return protocol;
  return std::nullopt;
}

}  // namespace salient::server
