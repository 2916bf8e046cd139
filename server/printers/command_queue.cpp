#include "server/printers/command_queue.hpp"

namespace salient::server {

void CommandQueue::push(PrinterCommand command) {
  struct Push {
    CommandQueue& q;
    void operator()(ConnectCommand) { q.connect_ = true, q.disconnect_ = false; }
    void operator()(DisconnectCommand) { q.disconnect_ = true, q.connect_ = false; }
    void operator()(EmergencyStopCommand) { q.estop_ = true; }
    void operator()(PrintCommand& p) { q.print_ = std::move(p); }
    void operator()(ConsoleCommand& c) { q.console_.push_back(std::move(c)); }
  };
  std::visit(Push{*this}, command);
}

std::optional<PrinterCommand> CommandQueue::take(bool linked, bool hold_print) {
  if (!linked) {
    if (!connect_) return std::nullopt;
    connect_ = false;
    return ConnectCommand{};
  }
  connect_ = false;
  if (disconnect_) return disconnect_ = false, PrinterCommand(DisconnectCommand{});
  if (estop_) return estop_ = false, PrinterCommand(EmergencyStopCommand{});
  if (!console_.empty()) {
    PrinterCommand c = std::move(console_.front());
    console_.pop_front();
    return c;
  }
  if (print_ && !hold_print) return PrinterCommand(*take_print());
  return std::nullopt;
}

std::optional<PrintCommand> CommandQueue::take_print() {
  std::optional<PrintCommand> p = std::move(print_);
  print_.reset();
  return p;
}

}  // namespace salient::server
