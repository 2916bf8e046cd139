// DaemonClient: salientd's REST API and its WebSocket events, for the CLI's client commands.
// Plain strings in, plain strings out; Beast lives in daemon_client.cpp only.
#pragma once

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace salient::cli {

struct DaemonAddress {
  std::string host = "127.0.0.1", port = "8080";
  std::string key;
};

// From --server (http://HOST:PORT) and --key, else $SALIENT_SERVER / $SALIENT_API_KEY, else
// http://127.0.0.1:8080 and the key in ./var/api-key (where `make run` keeps it).
DaemonAddress resolve_daemon(const std::string& server, const std::string& key);

struct DaemonReply {
  int status = 0;
  std::string body, content_type, location;
  std::string date;  // the Date header: the daemon's clock
};

// The daemon could not be reached, or answered with an error status (the message is its own).
class DaemonError : public std::runtime_error {
 public:
  DaemonError(int status, const std::string& message) : std::runtime_error(message), status_(status) {}
  int status() const { return status_; }

 private:
  int status_;
};

class DaemonClient {
 public:
  explicit DaemonClient(DaemonAddress address);
  ~DaemonClient();

  // Throws DaemonError for a refused connection or a status ≥ 400 (with the body's message).
  DaemonReply request(const std::string& method, const std::string& target, const std::string& body = {},
                      const std::string& content_type = "application/json");
  // POST multipart/form-data with the file under `field` and extra text fields.
  DaemonReply upload(const std::string& target, const std::string& field, const std::string& filename,
                     const std::string& bytes,
                     const std::vector<std::pair<std::string, std::string>>& fields);
  // Opens /api/v1/events, subscribes to `topics`, and calls `on_message` with each message (the
  // topics' current state first, then {"type": "subscribed"}, then events) until it returns false.
  void watch(const std::vector<std::string>& topics,
             const std::function<bool(const std::string&)>& on_message);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace salient::cli
