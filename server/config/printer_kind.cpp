#include "server/config/printer_kind.hpp"

#include <array>
#include <utility>

#include "core/common/name_table.hpp"

namespace salient::server {
namespace {

constexpr core::NameTable<PrinterKind, 3> kind_names{{
    {PrinterKind::sim, "sim"},
    {PrinterKind::serial, "serial"},
    {PrinterKind::tcp, "tcp"},
}};

constexpr core::NameTable<PrinterProtocol, 2> protocol_names{{
    {PrinterProtocol::marlin, "marlin"},
    {PrinterProtocol::s3g, "s3g"},
}};

}  // namespace

std::string_view to_string(PrinterKind k) {
  return core::name_in(kind_names, k, "serial");
}

std::optional<PrinterKind> printer_kind_from(std::string_view s) {
  return core::value_in(kind_names, s);
}

std::string_view to_string(PrinterProtocol p) {
  return core::name_in(protocol_names, p, "marlin");
}

std::optional<PrinterProtocol> printer_protocol_from(std::string_view s) {
  return core::value_in(protocol_names, s);
}

}  // namespace salient::server
