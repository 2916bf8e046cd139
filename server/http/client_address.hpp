// Who is on the other end when salientd runs behind a reverse proxy (nginx, see deploy/nginx/).
// Only a peer listed in [server] trusted_proxies is believed: its X-Forwarded-For names the client
// (the right-most address that is not itself a trusted proxy: the hops to its left were written
// by whoever sent the request and prove nothing), its X-Forwarded-Proto/-Host/-Prefix (or
// X-Script-Name, as OctoPrint reads it) the URL the client used. From anyone else these headers
// are ignored: a client cannot choose the address its rate limits and log lines are counted under.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace salient::server {

// An address or a network: "127.0.0.1", "::1", "10.0.0.0/8", "fd00::/8".
class TrustedProxies {
 public:
  TrustedProxies() = default;
  // Throws std::invalid_argument naming an entry that is neither.
  explicit TrustedProxies(const std::vector<std::string>& entries);
  bool trusts(std::string_view address) const;
  bool empty() const { return nets_.empty(); }

 private:
  struct Net {
    bool v6 = false;
    unsigned char bytes[16] = {};
    int bits = 0;
  };
  std::vector<Net> nets_;
};

// The client's address: the peer's, or from a trusted peer its X-Forwarded-For's right-most
// untrusted hop (a hop that is not an address ends the walk at the hop before it).
std::string client_address(const std::string& peer, std::string_view forwarded_for,
                           const TrustedProxies& trusted);

// The path prefix the client's URLs carry ("/salient", or "" at the root): from a trusted peer's
// X-Forwarded-Prefix or X-Script-Name when valid, else `configured` ([server] base_path).
std::string base_path_of(bool trusted_peer, std::string_view forwarded_prefix, std::string_view script_name,
                         const std::string& configured);
// "" or "/a/b" without a trailing slash; nullopt when it is not a plain path.
std::optional<std::string> normal_base_path(std::string_view path);

}  // namespace salient::server
