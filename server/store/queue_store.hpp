// QueueStore: the print queues (table print_queue): what waits to print, in order. A queue is
// named by its key: a printer's id, or "profile/P" for the farm-wide queue of printers with
// profile P (printer ids hold no '/'). Positions are 1..N per queue, renumbered on every change,
// so a client's "position" is always the entry's place in line.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "server/store/database.hpp"

namespace salient::server {

struct QueueEntry {
  long long id = 0;
  std::string printer_id;  // the queue's key: a printer id or "profile/P"
  std::string kind;        // "job" (a job's G-code) or "file" (an uploaded file)
  std::string ref;         // the job id or the file name
  long long position = 0;
  double created_at = 0;
  bool slicing = false;  // a job still being sliced (not stored: PrinterService tells)
};

class QueueStore {
 public:
  explicit QueueStore(Database& db) : db_(db) {}

  QueueEntry add(const std::string& printer_id, const std::string& kind, const std::string& ref, double now);
  std::vector<QueueEntry> list(const std::string& printer_id);
  std::optional<QueueEntry> get(const std::string& printer_id, long long id);
  bool remove(const std::string& printer_id, long long id);
  // Every entry, in any queue, for this job or file.
  std::vector<QueueEntry> holding(const std::string& kind, const std::string& ref);
  // Puts the entry at `position` (1..N), the others keeping their order. False: no such entry.
  bool move(const std::string& printer_id, long long id, long long position);

 private:
  void renumber(const std::string& printer_id, const std::vector<long long>& ids);
  Database& db_;
};

}  // namespace salient::server
