// PrintStore: prints (one row per print started on a printer, its progress written as it goes)
// and the named G-code files uploaded to print. A print left "printing" by a crash becomes
// "interrupted" at the next start, with the last acknowledged command to resume from.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "server/common/printer_state.hpp"
#include "server/store/database.hpp"

namespace salient::server {

struct PrintRecord {
  long long id = 0;
  std::string printer_id;
  std::optional<std::string> job_id;
  std::string file_digest, filename;
  PrintState state = PrintState::printing;
  long long confirmed = 0, total = 0;
  std::optional<std::string> reason;
  double started_at = 0;
  std::optional<double> finished_at;
};

struct StoredFile {
  std::string name, digest;
  long long size = 0;
  double uploaded_at = 0;
};

class PrintStore {
 public:
  explicit PrintStore(Database& db) : db_(db) {}

  PrintRecord create(const std::string& printer_id, const std::optional<std::string>& job_id,
                     const std::string& digest, const std::string& filename, long long total, double now);
  void set_progress(long long id, PrintState state, long long confirmed);
  void finish(long long id, PrintState state, long long confirmed, const std::optional<std::string>& reason,
              double now);
  std::optional<PrintRecord> get(long long id);
  std::optional<PrintRecord> latest(const std::string& printer_id);
  std::vector<PrintRecord> list(const std::string& printer_id, int limit);
  // At start: prints that were running when the daemon died; returns how many.
  int mark_interrupted(double now);

  void put_file(const std::string& name, const std::string& digest, long long size, double now);
  std::optional<StoredFile> file(const std::string& name);
  std::vector<StoredFile> files();
  bool remove_file(const std::string& name);

 private:
  Database& db_;
};

}  // namespace salient::server
