// The API key: made on first start (32 random bytes, hex), written to DATA/api-key with mode
// 0600 for the owner to read, and kept in the database only as its SHA-256.
#pragma once

#include <string>

#include "server/http/http_message.hpp"
#include "server/store/store.hpp"

namespace salient::server {

struct ApiKey {
  std::string key;   // only when it was made now (to show once); else empty
  bool created = false;
};

ApiKey ensure_api_key(Store& store);
// X-Api-Key: KEY or Authorization: Bearer KEY, checked against the stored digests.
bool request_has_valid_key(Store& store, const HttpRequest& request);

}  // namespace salient::server
