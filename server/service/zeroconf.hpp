// Zeroconf: salientd announced over mDNS/DNS-SD through Avahi as OctoPrint announces itself
// (_octoprint._tcp, and _http._tcp for browsers), so that Cura's and phone apps' discovery finds
// it. Avahi is reached over D-Bus; without a running avahi-daemon nothing is announced and the
// daemon goes on (logged), and when avahi-daemon comes back later the service is announced then.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace salient::server {

struct ZeroconfService {
  std::string name;  // the instance name people see ("salient on HOST"); Avahi renames on collision
  unsigned port = 0;
  std::vector<std::string> txt;  // "key=value" records
};

class ZeroconfAnnouncer {
 public:
  // Starts announcing (on Avahi's own thread); `log` gets one line per change (announced,
  // renamed, avahi-daemon gone or back).
  ZeroconfAnnouncer(std::vector<ZeroconfService> services, std::function<void(const std::string&)> log);
  ~ZeroconfAnnouncer();  // withdraws the services
  ZeroconfAnnouncer(const ZeroconfAnnouncer&) = delete;
  ZeroconfAnnouncer& operator=(const ZeroconfAnnouncer&) = delete;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

// salientd as OctoPrint announces itself: `name` (empty: "salient on HOSTNAME"), the port it
// listens on, TXT path=/, version and api (what OctoPrint's discovery plugin puts there), model.
std::unique_ptr<ZeroconfAnnouncer> announce_octoprint(const std::string& name, unsigned port,
                                                      std::function<void(const std::string&)> log);

}  // namespace salient::server
