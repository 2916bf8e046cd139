#include "server/metrics/metrics.hpp"

#include <cstdio>

namespace salient::server {

std::string prometheus_label(const std::string& value) {
  std::string out;
  for (char c : value) {
    if (c == '\\' || c == '"')
      out += '\\', out += c;
    else if (c == '\n')
      out += "\\n";
    else
      out += c;
  }
  return out;
}

void Metrics::http_response(const std::string& method, const std::string& route, int status, double seconds) {
  std::lock_guard lock(mutex_);
  ++requests_[{method, route, status}];
  auto& s = request_seconds_[route];
  ++s.first;
  s.second += seconds;
}

void Metrics::job_finished(const std::string& state, double seconds) {
  std::lock_guard lock(mutex_);
  auto& s = job_seconds_[state];
  ++s.first;
  s.second += seconds;
}

namespace {

std::string number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

std::string Metrics::render() const {
  std::lock_guard lock(mutex_);
  std::string out;
  out += "# HELP salient_http_requests_total HTTP requests answered, by route pattern and status.\n";
  out += "# TYPE salient_http_requests_total counter\n";
  for (const auto& [key, n] : requests_) {
    const auto& [method, route, status] = key;
    out += "salient_http_requests_total{method=\"" + prometheus_label(method) + "\",route=\"" +
           prometheus_label(route) + "\",status=\"" + std::to_string(status) + "\"} " + std::to_string(n) +
           "\n";
  }
  out += "# HELP salient_http_request_seconds Time to answer HTTP requests, by route pattern.\n";
  out += "# TYPE salient_http_request_seconds summary\n";
  for (const auto& [route, s] : request_seconds_) {
    const std::string label = "{route=\"" + prometheus_label(route) + "\"}";
    out += "salient_http_request_seconds_count" + label + " " + std::to_string(s.first) + "\n";
    out += "salient_http_request_seconds_sum" + label + " " + number(s.second) + "\n";
  }
  out += "# HELP salient_job_seconds Wall time of finished slicing jobs, by final state.\n";
  out += "# TYPE salient_job_seconds summary\n";
  for (const auto& [state, s] : job_seconds_) {
    const std::string label = "{state=\"" + prometheus_label(state) + "\"}";
    out += "salient_job_seconds_count" + label + " " + std::to_string(s.first) + "\n";
    out += "salient_job_seconds_sum" + label + " " + number(s.second) + "\n";
  }
  return out;
}

}  // namespace salient::server
