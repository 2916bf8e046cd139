// The Boost.Asio transports: serial_port (8N1, no flow control, raw) and a TCP socket. Reads wait
// with io_context::run_for, so one thread drives a link without extra threads or busy polling.
#include <linux/serial.h>
#include <sys/ioctl.h>
#include <termios.h>

#include <array>
#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/serial_port.hpp>
#include <boost/asio/write.hpp>
#include <cstring>
#include <thread>

#include "protocol/serial/custom_baud.hpp"
#include "protocol/serial/transport.hpp"

namespace salient::protocol::serial {
namespace {

namespace asio = boost::asio;

bool standard_baud(unsigned baud) {
  for (unsigned b : {9600u, 19200u, 38400u, 57600u, 115200u, 230400u, 460800u, 500000u, 921600u, 1000000u})
    if (b == baud) return true;
  return false;
}

// Reads and writes any Asio stream with a deadline on reads.
template <typename Stream>
class AsioTransport : public Transport {
 public:
  AsioTransport(std::unique_ptr<asio::io_context> io, Stream stream, std::string name)
      : io_(std::move(io)), stream_(std::move(stream)), name_(std::move(name)) {}

  void write(std::string_view bytes) override {
    boost::system::error_code ec;
    asio::write(stream_, asio::buffer(bytes.data(), bytes.size()), ec);
    if (ec) throw LinkError(name_ + ": the printer disconnected (write failed: " + ec.message() + ")");
  }

  std::string read(std::chrono::microseconds timeout) override {
    boost::system::error_code result = asio::error::would_block;
    std::size_t n = 0;
    stream_.async_read_some(asio::buffer(buffer_), [&](const boost::system::error_code& ec, std::size_t got) {
      result = ec;
      n = got;
    });
    io_->restart();
    io_->run_for(timeout);
    if (result == asio::error::would_block) {  // nothing came in time
      stream_.cancel();
      io_->restart();
      io_->run();
      if (result == asio::error::operation_aborted) result = {};
    }
    if (result && result != asio::error::operation_aborted)
      throw LinkError(name_ + ": the printer disconnected (" + result.message() + ")");
    return std::string(buffer_.data(), n);
  }

  void discard_input() override {
    if constexpr (std::is_same_v<Stream, asio::serial_port>) ::tcflush(stream_.native_handle(), TCIFLUSH);
  }

  std::string describe() const override { return name_; }

 private:
  std::unique_ptr<asio::io_context> io_;
  Stream stream_;
  std::string name_;
  std::array<char, 65536> buffer_{};
};

}  // namespace

std::unique_ptr<Transport> open_serial(const SerialOptions& o) {
  auto io = std::make_unique<asio::io_context>(1);
  asio::serial_port port(*io);
  boost::system::error_code ec;
  port.open(o.device, ec);
  if (ec) throw LinkError(o.device + ": cannot open: " + ec.message());
  using base = asio::serial_port_base;
  port.set_option(base::character_size(8), ec);
  port.set_option(base::parity(base::parity::none), ec);
  port.set_option(base::stop_bits(base::stop_bits::one), ec);
  port.set_option(base::flow_control(base::flow_control::none), ec);
  const int fd = port.native_handle();
  if (standard_baud(o.baud)) {
    port.set_option(base::baud_rate(o.baud), ec);
    if (ec) throw LinkError(o.device + ": cannot set " + std::to_string(o.baud) + " baud: " + ec.message());
  } else if (int err = set_custom_baud(fd, o.baud); err != 0) {
    throw LinkError(o.device + ": cannot set " + std::to_string(o.baud) + " baud: " + std::strerror(err));
  }
  if (o.low_latency) {  // USB adapters otherwise hold bytes up to 16 ms: ping-pong would crawl
    serial_struct ss{};
    if (::ioctl(fd, TIOCGSERIAL, &ss) == 0) {
      ss.flags |= ASYNC_LOW_LATENCY;
      ::ioctl(fd, TIOCSSERIAL, &ss);
    }
  }
  if (o.reset) {
    int dtr = TIOCM_DTR;
    ::ioctl(fd, TIOCMBIC, &dtr);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    ::ioctl(fd, TIOCMBIS, &dtr);
  }
  return std::make_unique<AsioTransport<asio::serial_port>>(std::move(io), std::move(port), o.device);
}

std::unique_ptr<Transport> open_tcp(const std::string& host_port) {
  const std::size_t colon = host_port.rfind(':');
  if (colon == std::string::npos || colon + 1 == host_port.size())
    throw LinkError("--tcp " + host_port + ": expected HOST:PORT");
  auto io = std::make_unique<asio::io_context>(1);
  asio::ip::tcp::resolver resolver(*io);
  boost::system::error_code ec;
  auto endpoints = resolver.resolve(host_port.substr(0, colon), host_port.substr(colon + 1), ec);
  if (ec) throw LinkError(host_port + ": cannot resolve: " + ec.message());
  asio::ip::tcp::socket socket(*io);
  asio::connect(socket, endpoints, ec);
  if (ec) throw LinkError(host_port + ": cannot connect: " + ec.message());
  socket.set_option(asio::ip::tcp::no_delay(true), ec);
  return std::make_unique<AsioTransport<asio::ip::tcp::socket>>(std::move(io), std::move(socket), host_port);
}

}  // namespace salient::protocol::serial
