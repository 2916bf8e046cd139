#include "server/printers/progress_saver.hpp"

namespace salient::server {

void ProgressSaver::start() {
  std::lock_guard lock(mutex_);
  if (thread_.joinable()) return;
  stopping_ = false;
  thread_ = std::thread([this] { run(); });
}

void ProgressSaver::request() {
  {
    std::lock_guard lock(mutex_);
    requested_ = true;
  }
  wake_.notify_one();
}

void ProgressSaver::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
}

void ProgressSaver::run() {
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return requested_ || stopping_; });
    if (stopping_) return;
    requested_ = false;
    lock.unlock();
    const bool saved = save_();
    lock.lock();
    // Refused: the next writes wait, so that a full disk or an absent database is not asked 50
    // times a second; what is asked meanwhile is written after.
    if (!saved) wake_.wait_for(lock, kPauseAfterFailure, [this] { return stopping_; });
  }
}

}  // namespace salient::server
