#include "server/http/client_address.hpp"

#include <arpa/inet.h>

#include <cstring>
#include <stdexcept>

namespace salient::server {
namespace {

struct Parsed {
  bool v6 = false;
  unsigned char bytes[16] = {};
};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// An IPv4 or IPv6 address (an IPv4-mapped IPv6 one counts as IPv4, as a dual-stack socket reports it).
std::optional<Parsed> parse(std::string_view text) {
  if (text.size() > 45) return std::nullopt;
  const std::string s(text);
  Parsed p;
  if (inet_pton(AF_INET, s.c_str(), p.bytes) == 1) return p;
  unsigned char b[16];
  if (inet_pton(AF_INET6, s.c_str(), b) != 1) return std::nullopt;
  static const unsigned char mapped[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xff, 0xff};
  if (std::memcmp(b, mapped, 12) == 0) {
    std::memcpy(p.bytes, b + 12, 4);
    return p;
  }
  p.v6 = true;
  std::memcpy(p.bytes, b, 16);
  return p;
}

}  // namespace

TrustedProxies::TrustedProxies(const std::vector<std::string>& entries) {
  for (const std::string& e : entries) {
    const std::size_t slash = e.find('/');
    const std::optional<Parsed> a = parse(e.substr(0, slash));
    if (!a) throw std::invalid_argument("'" + e + "' is not an address or a network (10.0.0.0/8)");
    Net n;
    n.v6 = a->v6;
    std::memcpy(n.bytes, a->bytes, 16);
    n.bits = n.v6 ? 128 : 32;
    if (slash != std::string::npos) {
      const std::string bits = e.substr(slash + 1);
      if (bits.empty() || bits.size() > 3 || bits.find_first_not_of("0123456789") != std::string::npos ||
          std::stoi(bits) > n.bits)
        throw std::invalid_argument("'" + e + "': the prefix length must be 0 to " + std::to_string(n.bits));
      n.bits = std::stoi(bits);
    }
    nets_.push_back(n);
  }
}

bool TrustedProxies::trusts(std::string_view address) const {
  const std::optional<Parsed> a = parse(address);
  if (!a) return false;
  for (const Net& n : nets_) {
    if (n.v6 != a->v6) continue;
    const int whole = n.bits / 8, rest = n.bits % 8;
    if (std::memcmp(n.bytes, a->bytes, static_cast<std::size_t>(whole)) != 0) continue;
    const unsigned char mask = static_cast<unsigned char>(0xff << (8 - rest));
    if (rest == 0 || (n.bytes[whole] & mask) == (a->bytes[whole] & mask)) return true;
  }
  return false;
}

std::string client_address(const std::string& peer, std::string_view forwarded_for,
                           const TrustedProxies& trusted) {
  if (!trusted.trusts(peer) || forwarded_for.empty()) return peer;
  std::string client = peer;
  while (true) {
    const std::size_t comma = forwarded_for.rfind(',');
    const std::string_view hop =
        trim(comma == std::string_view::npos ? forwarded_for : forwarded_for.substr(comma + 1));
    if (!parse(hop)) return client;  // garbage (or "unknown"): the last hop we could read
    client = std::string(hop);
    if (!trusted.trusts(hop) || comma == std::string_view::npos) return client;
    forwarded_for = forwarded_for.substr(0, comma);
  }
}

std::optional<std::string> normal_base_path(std::string_view path) {
  if (path.empty() || path == "/") return std::string();
  if (path.front() != '/' || path.size() > 256) return std::nullopt;
  for (const char c : path)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || std::strchr("/-._~", c))) return std::nullopt;
  if (path.find("//") != std::string_view::npos || path.find("/..") != std::string_view::npos)
    return std::nullopt;
  std::string out(path);
  while (out.size() > 1 && out.back() == '/') out.pop_back();
  return out;
}

std::string base_path_of(bool trusted_peer, std::string_view forwarded_prefix, std::string_view script_name,
                         const std::string& configured) {
  if (trusted_peer)
    for (const std::string_view header : {forwarded_prefix, script_name})
      if (!header.empty())
        if (const auto p = normal_base_path(trim(header))) return *p;
  return configured;
}

}  // namespace salient::server
