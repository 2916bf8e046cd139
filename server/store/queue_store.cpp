#include "server/store/queue_store.hpp"

#include <algorithm>

namespace salient::server {
namespace {

constexpr const char* columns = "id, printer_id, kind, ref, position, created_at";

QueueEntry read_entry(const Database::Statement& q) {
  return {q.integer(0), q.text(1), q.text(2), q.text(3), q.integer(4), q.real(5)};
}

}  // namespace

QueueEntry QueueStore::add(const std::string& printer_id, const std::string& kind, const std::string& ref,
                           double now) {
  Database::Transaction t(db_);
  auto q = db_.prepare(
      "INSERT INTO print_queue (printer_id, kind, ref, position, created_at) VALUES (?1, ?2, ?3, "
      "(SELECT COALESCE(MAX(position), 0) + 1 FROM print_queue WHERE printer_id = ?1), ?4) RETURNING id");
  q.bind(1, std::string_view(printer_id))
      .bind(2, std::string_view(kind))
      .bind(3, std::string_view(ref))
      .bind(4, now);
  q.step();
  const long long id = q.integer(0);
  q.run();
  t.commit();
  return *get(printer_id, id);
}

std::vector<QueueEntry> QueueStore::list(const std::string& printer_id) {
  auto q = db_.prepare(std::string("SELECT ") + columns +
                       " FROM print_queue WHERE printer_id = ? ORDER BY position, id");
  q.bind(1, std::string_view(printer_id));
  std::vector<QueueEntry> out;
  while (q.step()) out.push_back(read_entry(q));
  return out;
}

std::vector<QueueEntry> QueueStore::holding(const std::string& kind, const std::string& ref) {
  auto q = db_.prepare(std::string("SELECT ") + columns +
                       " FROM print_queue WHERE kind = ? AND ref = ? ORDER BY printer_id, position");
  q.bind(1, std::string_view(kind)).bind(2, std::string_view(ref));
  std::vector<QueueEntry> out;
  while (q.step()) out.push_back(read_entry(q));
  return out;
}

std::optional<QueueEntry> QueueStore::get(const std::string& printer_id, long long id) {
  auto q =
      db_.prepare(std::string("SELECT ") + columns + " FROM print_queue WHERE printer_id = ? AND id = ?");
  q.bind(1, std::string_view(printer_id)).bind(2, static_cast<std::int64_t>(id));
  if (!q.step()) return std::nullopt;
  QueueEntry e = read_entry(q);
  q.run();
  return e;
}

bool QueueStore::remove(const std::string& printer_id, long long id) {
  Database::Transaction t(db_);
  db_.prepare("DELETE FROM print_queue WHERE printer_id = ? AND id = ?")
      .bind(1, std::string_view(printer_id))
      .bind(2, static_cast<std::int64_t>(id))
      .run();
  if (db_.changes() == 0) return false;
  std::vector<long long> ids;
  for (const QueueEntry& e : list(printer_id)) ids.push_back(e.id);
  renumber(printer_id, ids);
  t.commit();
  return true;
}

bool QueueStore::move(const std::string& printer_id, long long id, long long position) {
  Database::Transaction t(db_);
  std::vector<long long> ids;
  for (const QueueEntry& e : list(printer_id)) ids.push_back(e.id);
  const auto it = std::find(ids.begin(), ids.end(), id);
  if (it == ids.end()) return false;
  ids.erase(it);
  const long long at = std::clamp<long long>(position, 1, static_cast<long long>(ids.size()) + 1);
  ids.insert(ids.begin() + (at - 1), id);
  renumber(printer_id, ids);
  t.commit();
  return true;
}

void QueueStore::renumber(const std::string& printer_id, const std::vector<long long>& ids) {
  auto q = db_.prepare("UPDATE print_queue SET position = ? WHERE printer_id = ? AND id = ?");
  for (std::size_t i = 0; i < ids.size(); ++i)
    q.bind(1, static_cast<std::int64_t>(i + 1))
        .bind(2, std::string_view(printer_id))
        .bind(3, static_cast<std::int64_t>(ids[i]))
        .run();
}

}  // namespace salient::server
