// The API key: made on first start (32 random bytes, hex), written to DATA/api-key with mode
// 0600 for the owner to read, and kept in the database only as its SHA-256.
#pragma once

#include <string>
#include <vector>

#include "server/http/http_message.hpp"
#include "server/store/store.hpp"

namespace salient::server {

struct ApiKey {
  std::string key;  // only when it was made now (to show once); else empty
  bool created = false;
};

ApiKey ensure_api_key(Store& store);
// The digests of the valid keys, read once at start: checking a request touches no database.
class ApiKeys {
 public:
  explicit ApiKeys(Store& store);
  // X-Api-Key: KEY, Authorization: Bearer KEY, or ?apikey=KEY (as OctoPrint; for browsers'
  // WebSockets, which cannot set headers).
  bool valid(const HttpRequest& request) const;
  bool valid_key(std::string_view key) const;

 private:
  std::vector<std::string> digests_;
};

}  // namespace salient::server
