// TerminalTap: a Transport that passes everything through and tells, line by line, what went to
// the printer and what came back — the daemon's terminal/{id} topic. `wanted` is asked before each
// chunk so that nothing is split or formatted while nobody watches. A binary protocol (s3g) is told
// in hex, a line per write (one packet) and per chunk read.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "protocol/serial/transport.hpp"

namespace salient::server {

class TerminalTap : public protocol::serial::Transport {
 public:
  using LineFn = std::function<void(bool sent, std::string_view line)>;
  TerminalTap(std::unique_ptr<protocol::serial::Transport> inner, std::function<bool()> wanted,
              LineFn on_line, bool binary = false)
      : inner_(std::move(inner)), wanted_(std::move(wanted)), on_line_(std::move(on_line)), binary_(binary) {}

  void write(std::string_view bytes) override {
    inner_->write(bytes);
    if (wanted_()) tell(bytes, sent_partial_, true);
  }
  std::string read(std::chrono::microseconds timeout) override {
    std::string bytes = inner_->read(timeout);
    if (!bytes.empty() && wanted_()) tell(bytes, received_partial_, false);
    return bytes;
  }
  void discard_input() override { inner_->discard_input(); }
  std::string describe() const override { return inner_->describe(); }

 private:
  void tell(std::string_view bytes, std::string& partial, bool sent) {
    if (!binary_) return split(bytes, partial, sent);
    static constexpr char digits[] = "0123456789abcdef";
    std::string hex;
    for (unsigned char b : bytes.substr(0, 64)) {
      if (!hex.empty()) hex += ' ';
      hex += digits[b >> 4];
      hex += digits[b & 15];
    }
    if (bytes.size() > 64) hex += " …";
    on_line_(sent, hex);
  }
  void split(std::string_view bytes, std::string& partial, bool sent) {
    partial.append(bytes);
    std::size_t start = 0;
    for (std::size_t nl; (nl = partial.find('\n', start)) != std::string::npos; start = nl + 1) {
      std::string_view line(partial.data() + start, nl - start);
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      if (!line.empty()) on_line_(sent, line);
    }
    partial.erase(0, start);
    if (partial.size() > 4096) partial.clear();
  }

  std::unique_ptr<protocol::serial::Transport> inner_;
  std::function<bool()> wanted_;
  LineFn on_line_;
  bool binary_;
  std::string sent_partial_, received_partial_;
};

}  // namespace salient::server
