// DatabaseBlobs: files kept in the database itself (PostgreSQL's table blobs, made by its backend:
// digest, chunk_no, data), so that the nodes of a farm share files through the one service they
// share already. Chunks of 1 MiB: a file goes in and comes out a chunk per statement, never whole.
#pragma once

#include <functional>

#include "server/store/database.hpp"
#include "server/store/file_store.hpp"

namespace salient::server {

class DatabaseBlobs final : public RemoteFiles {
 public:
  static constexpr std::size_t chunk_bytes = 1u << 20;

  // `connection` gives the calling thread's connection (Store::db).
  explicit DatabaseBlobs(std::function<Database&()> connection) : db_(std::move(connection)) {}

  bool has(std::string_view digest) override;
  void upload(std::string_view digest, const std::filesystem::path& file) override;
  bool download(std::string_view digest, const std::function<void(std::string_view)>& sink) override;
  void remove(std::string_view digest) override;

 private:
  std::function<Database&()> db_;
};

}  // namespace salient::server
