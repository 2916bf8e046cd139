// Metrics: counters the daemon keeps for /metrics (Prometheus text format 0.0.4): HTTP requests
// by route and status with their duration, and finished jobs by state with their seconds.
// Gauges that the database or the printers know (jobs by state, queue length, print lines) are
// read when scraped, by the route.
#pragma once

#include <map>
#include <mutex>
#include <string>
#include <tuple>

namespace salient::server {

class Metrics {
 public:
  void http_response(const std::string& method, const std::string& route, int status, double seconds);
  void job_finished(const std::string& state, double seconds);
  // The counters, as Prometheus text (HELP and TYPE lines included).
  std::string render() const;

 private:
  mutable std::mutex mutex_;
  std::map<std::tuple<std::string, std::string, int>, long long> requests_;
  std::map<std::string, std::pair<long long, double>> request_seconds_;  // by route: count, sum
  std::map<std::string, std::pair<long long, double>> job_seconds_;      // by final state: count, sum
};

// A label value with \, " and newlines escaped.
std::string prometheus_label(const std::string& value);

}  // namespace salient::server
