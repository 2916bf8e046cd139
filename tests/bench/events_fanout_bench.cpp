// events_fanout_bench: N WebSocket subscribers on salientd's /api/v1/events ("jobs"), then K
// jobs submitted; every subscriber must receive every state change of every job (queued, each
// phase, done), in order. Prints how many each got, and how long the fan-out took.
//   events_fanout_bench HOST PORT KEY MODEL SUBSCRIBERS JOBS
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

struct Subscriber : std::enable_shared_from_this<Subscriber> {
  explicit Subscriber(asio::io_context& io) : ws(io) {}
  websocket::stream<beast::tcp_stream> ws;
  beast::flat_buffer buffer;
  bool subscribed = false;
  std::map<std::string, std::vector<std::string>> steps;  // job → its distinct (state/phase) steps
  int done = 0, messages = 0;
  Clock::time_point last;

  void read(int jobs) {
    ws.async_read(buffer, [self = shared_from_this(), jobs](beast::error_code ec, std::size_t) {
      if (ec) {
        std::fprintf(stderr, "subscriber: %s\n", ec.message().c_str());
        return;
      }
      const json m = json::parse(beast::buffers_to_string(self->buffer.data()));
      self->buffer.consume(self->buffer.size());
      ++self->messages;
      if (m["type"] == "subscribed") self->subscribed = true;
      if (m["type"] == "job") {
        const json& d = m["data"];
        const std::string step = d["state"].get<std::string>() +
                                 (d["state"] == "running" ? "/" + d["phase"].get<std::string>() : "");
        auto& s = self->steps[d["id"].get<std::string>()];
        if (s.empty() || s.back() != step) s.push_back(step);
        if (d["state"] == "done") ++self->done, self->last = Clock::now();
      }
      if (self->done < jobs) self->read(jobs);
    });
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 7) {
    std::fprintf(stderr, "usage: %s HOST PORT KEY MODEL SUBSCRIBERS JOBS\n", argv[0]);
    return 2;
  }
  const std::string host = argv[1], port = argv[2], key = argv[3], model = argv[4];
  const int n = std::stoi(argv[5]), jobs = std::stoi(argv[6]);
  asio::io_context io;
  const auto endpoints = tcp::resolver(io).resolve(host, port);
  std::vector<std::shared_ptr<Subscriber>> subs;
  for (int i = 0; i < n; ++i) {
    auto s = std::make_shared<Subscriber>(io);
    beast::get_lowest_layer(s->ws).connect(endpoints);
    s->ws.set_option(
        websocket::stream_base::decorator([key](websocket::request_type& r) { r.set("X-Api-Key", key); }));
    s->ws.handshake(host, "/api/v1/events");
    s->ws.write(asio::buffer(std::string(R"({"subscribe": ["jobs"]})")));
    subs.push_back(s);
  }
  for (auto& s : subs) s->read(jobs);
  while (!std::all_of(subs.begin(), subs.end(), [](const auto& s) { return s->subscribed; })) io.run_one();

  std::ifstream f(model, std::ios::binary);
  std::stringstream bytes;
  bytes << f.rdbuf();
  const std::string name = model.substr(model.find_last_of('/') + 1);
  const auto t0 = Clock::now();
  for (int j = 0; j < jobs; ++j) {  // distinct settings: no reuse of an earlier result
    beast::tcp_stream stream(io);
    stream.connect(endpoints);
    const std::string settings = "%7B%22height%22%3A" + std::to_string(10 + j) + "%7D";
    http::request<http::string_body> req(http::verb::post,
                                         "/api/v1/jobs?filename=" + name + "&settings=" + settings, 11);
    req.set(http::field::host, host);
    req.set("X-Api-Key", key);
    req.body() = bytes.str();
    req.prepare_payload();
    http::write(stream, req);
    beast::flat_buffer b;
    http::response<http::string_body> res;
    http::read(stream, b, res);
    if (res.result_int() >= 300) {
      std::fprintf(stderr, "submit: %d %s\n", res.result_int(), res.body().c_str());
      return 1;
    }
  }
  const auto deadline = Clock::now() + std::chrono::minutes(5);
  while (Clock::now() < deadline &&
         !std::all_of(subs.begin(), subs.end(), [&](const auto& s) { return s->done >= jobs; }))
    io.run_one_for(std::chrono::milliseconds(100));

  // Every subscriber's steps for every job must be the full sequence, in order.
  const std::vector<std::string> want = {"queued",       "running/load",      "running/saliency",
                                         "running/plan", "running/toolpaths", "done"};
  int complete = 0;
  long long messages = 0, changes = 0;
  double slowest = 0;
  for (const auto& s : subs) {
    bool ok = static_cast<int>(s->steps.size()) == jobs;
    for (const auto& [id, steps] : s->steps) {
      ok = ok && steps == want;
      changes += static_cast<long long>(steps.size());
    }
    complete += ok;
    messages += s->messages;
    slowest = std::max(slowest, std::chrono::duration<double>(s->last - t0).count());
  }
  std::printf(
      "subscribers %d, jobs %d: %d of %d saw all %zu state changes of every job in order "
      "(%lld state changes, %lld messages in all incl. progress); last 'done' delivered %.2f s after the "
      "first submit\n",
      n, jobs, complete, n, want.size(), changes, messages, slowest);
  return complete == n ? 0 : 1;
}
