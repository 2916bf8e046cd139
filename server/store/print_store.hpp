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
  double filament_mm = 0;     // pushed up to the last confirmed command (net of retractions)
  double paused_seconds = 0;  // of the time from start to end
};

// What a print used so far, written with its progress.
struct PrintUsage {
  double filament_mm = 0, paused_seconds = 0;
};

// A printer's (or the farm's) history in sums, as Moonraker's history totals: every print ended,
// the time from start to end and the time printing (pauses left out), the filament, the longest.
struct PrintTotals {
  long long prints = 0, finished = 0, cancelled = 0, failed = 0, interrupted = 0;
  double total_seconds = 0, print_seconds = 0, filament_mm = 0;
  double longest_seconds = 0, longest_print_seconds = 0;
};

// An uploaded file; `name` is its path in the file area ("a/b/c.gcode", "c.gcode" at the top).
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
  void set_progress(long long id, PrintState state, long long confirmed, PrintUsage usage);
  void finish(long long id, PrintState state, long long confirmed, const std::optional<std::string>& reason,
              double now, PrintUsage usage);
  std::optional<PrintRecord> get(long long id);
  std::optional<PrintRecord> latest(const std::string& printer_id);
  std::vector<PrintRecord> list(const std::string& printer_id, int limit);
  // The ended prints of one printer, or of all when `printer_id` is empty.
  PrintTotals totals(const std::string& printer_id);
  // At start: prints that were running when the daemon died; returns how many.
  int mark_interrupted(double now);

  void put_file(const std::string& name, const std::string& digest, long long size, double now);
  std::optional<StoredFile> file(const std::string& name);
  std::vector<StoredFile> files();
  bool remove_file(const std::string& name);

  // Folders (paths without a leading '/'). put_folder also makes the missing ancestors; it is
  // a no-op for one that exists.
  void put_folder(const std::string& path, double now);
  bool folder_exists(const std::string& path);
  std::vector<std::string> folders();
  // The folder, its sub-folders and the files under it, in one transaction: the removed files.
  std::vector<StoredFile> remove_folder(const std::string& path);
  // Renames a file, or a folder with everything under it; copies likewise (a copy shares the
  // content, which is addressed by digest). The destination must not exist (the caller checks).
  // Queued prints of moved files follow them.
  void move_file(const std::string& from, const std::string& to);
  void move_folder(const std::string& from, const std::string& to);
  void copy_file(const std::string& from, const std::string& to, double now);
  void copy_folder(const std::string& from, const std::string& to, double now);

 private:
  Database& db_;
};

}  // namespace salient::server
