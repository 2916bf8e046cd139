#include "server/store/database_blobs.hpp"

#include <fstream>
#include <vector>

namespace salient::server {

bool DatabaseBlobs::has(std::string_view digest) {
  auto q = db_().prepare("SELECT 1 FROM blobs WHERE digest = ? AND chunk_no = 0");
  q.bind(1, digest);
  const bool found = q.step();
  if (found) q.run();
  return found;
}

// One transaction: other nodes see the whole file or none of it. A plain BEGIN, not the writers'
// lock (Database::Transaction): a long upload must not hold up job and print updates. Two nodes
// uploading the same bytes at once: the second waits on the first's rows, then adds nothing.
void DatabaseBlobs::upload(std::string_view digest, const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw StoreError("cannot read " + file.string() + " to store it");
  Database& db = db_();
  const bool own = !db.in_transaction();  // inside a caller's transaction: part of it
  if (own) db.exec("BEGIN");
  try {
    auto q = db.prepare("INSERT INTO blobs (digest, chunk_no, data) VALUES (?, ?, ?) ON CONFLICT DO NOTHING");
    std::vector<char> buffer(chunk_bytes);
    std::int64_t chunk = 0;
    do {
      in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
      const auto n = static_cast<std::size_t>(in.gcount());
      if (n == 0 && chunk > 0) break;  // an empty file still has its chunk 0, its mark of presence
      q.bind(1, digest).bind(2, chunk++).bind_blob(3, std::string_view(buffer.data(), n)).run();
    } while (in);
    if (in.bad()) throw StoreError("cannot read " + file.string() + " to store it");
    if (own) db.exec("COMMIT");
  } catch (...) {
    if (own) {
      try {
        db.exec("ROLLBACK");
      } catch (...) {
      }
    }
    throw;
  }
}

bool DatabaseBlobs::download(std::string_view digest, const std::function<void(std::string_view)>& sink) {
  auto q = db_().prepare("SELECT data FROM blobs WHERE digest = ? AND chunk_no = ?");
  for (std::int64_t chunk = 0;; ++chunk) {
    q.bind(1, digest).bind(2, chunk);
    if (!q.step()) return chunk > 0;
    sink(q.blob(0));
    q.run();
  }
}

void DatabaseBlobs::remove(std::string_view digest) {
  db_().prepare("DELETE FROM blobs WHERE digest = ?").bind(1, digest).run();
}

}  // namespace salient::server
