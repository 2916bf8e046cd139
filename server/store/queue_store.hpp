// QueueStore: each printer's print queue (table print_queue): what waits to print there, in
// order. Positions are 1..N per printer, renumbered on every change, so a client's "position"
// is always the entry's place in line.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "server/store/database.hpp"

namespace salient::server {

struct QueueEntry {
  long long id = 0;
  std::string printer_id;
  std::string kind;  // "job" (a job's G-code) or "file" (an uploaded file)
  std::string ref;   // the job id or the file name
  long long position = 0;
  double created_at = 0;
};

class QueueStore {
 public:
  explicit QueueStore(Database& db) : db_(db) {}

  QueueEntry add(const std::string& printer_id, const std::string& kind, const std::string& ref, double now);
  std::vector<QueueEntry> list(const std::string& printer_id);
  std::optional<QueueEntry> get(const std::string& printer_id, long long id);
  bool remove(const std::string& printer_id, long long id);
  // Puts the entry at `position` (1..N), the others keeping their order. False: no such entry.
  bool move(const std::string& printer_id, long long id, long long position);

 private:
  void renumber(const std::string& printer_id, const std::vector<long long>& ids);
  Database& db_;
};

}  // namespace salient::server
