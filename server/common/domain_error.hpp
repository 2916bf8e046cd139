// DomainError: what the daemon's services (jobs, printers, files) refuse, said without HTTP.
// Services throw the kind that fits; the router alone turns a kind into a status (bad_request
// 400, not_found 404, conflict 409, unsupported 415, unprocessable 422, too_busy 429), so that
// server/jobs and server/printers need not know they are served over HTTP. `code` is the
// machine-readable name clients see in {"error": {code, message}}.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>

namespace salient::server {

enum class ErrorKind { bad_request, not_found, conflict, unsupported, unprocessable, too_busy };

class DomainError : public std::runtime_error {
 public:
  DomainError(ErrorKind kind, std::string code, const std::string& message)
      : std::runtime_error(message), kind_(kind), code_(std::move(code)) {}
  ErrorKind kind() const { return kind_; }
  const std::string& code() const { return code_; }
  // too_busy: when to try again (Retry-After), in seconds.
  std::optional<int> retry_after() const { return retry_after_; }
  DomainError& retry_after(int seconds) {
    retry_after_ = seconds;
    return *this;
  }

 private:
  ErrorKind kind_;
  std::string code_;
  std::optional<int> retry_after_;
};

struct BadRequest : DomainError {
  BadRequest(std::string code, const std::string& message)
      : DomainError(ErrorKind::bad_request, std::move(code), message) {}
};
struct NotFound : DomainError {
  explicit NotFound(const std::string& message) : DomainError(ErrorKind::not_found, "not_found", message) {}
};
struct Conflict : DomainError {
  Conflict(std::string code, const std::string& message)
      : DomainError(ErrorKind::conflict, std::move(code), message) {}
};
struct Unsupported : DomainError {
  Unsupported(std::string code, const std::string& message)
      : DomainError(ErrorKind::unsupported, std::move(code), message) {}
};
struct Unprocessable : DomainError {
  Unprocessable(std::string code, const std::string& message)
      : DomainError(ErrorKind::unprocessable, std::move(code), message) {}
};
struct TooBusy : DomainError {
  TooBusy(std::string code, const std::string& message, int retry_after_seconds)
      : DomainError(ErrorKind::too_busy, std::move(code), message) {
    retry_after(retry_after_seconds);
  }
};

}  // namespace salient::server
