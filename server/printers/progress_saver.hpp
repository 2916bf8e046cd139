// ProgressSaver: a print's progress written to the database on a thread of its own, so that the
// printer's thread, which streams the print, never waits on the database (a PostgreSQL frozen for
// 21 s stopped a print for 21 s). Requests coalesce: each write reads the progress as it is then.
// A write that fails (a full disk, the database away) pauses them for a while; the print goes on.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace salient::server {

class ProgressSaver {
 public:
  static constexpr std::chrono::seconds kPauseAfterFailure{5};
  // `save`: writes the progress now; false when the store refused it.
  explicit ProgressSaver(std::function<bool()> save) : save_(std::move(save)) {}
  ~ProgressSaver() { stop(); }
  ProgressSaver(const ProgressSaver&) = delete;
  ProgressSaver& operator=(const ProgressSaver&) = delete;

  void start();
  // A write is wanted: made soon on the saver's thread. Never waits on the database.
  void request();
  // Ends the thread once a write under way is done; a requested one not begun is dropped.
  void stop();

 private:
  void run();
  std::function<bool()> save_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool requested_ = false, stopping_ = false;
  std::thread thread_;
};

}  // namespace salient::server
