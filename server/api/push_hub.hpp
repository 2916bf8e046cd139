// PushHub: OctoPrint's push socket, /sockjs/websocket (a raw WebSocket, as FDM Monster and OctoPod
// connect). It watches OctoPrint's printer (the first configured: default_printer) and serves its
// clients (PushChannel): the printer's part of each `current` is built once per change and shared;
// each client adds what is new for it — temperatures (from the printer's TemperatureHistory) and
// terminal lines (the last kMaxLogs, kept here) since its last update.
//
// One thread of its own does the work, so that a printer's thread only sets a flag: it pulls the
// printer's changes of state in order (Printer::state_changes_since, never missed however short),
// turns each into a `current` that every client is sent and into events (push_events), builds the
// newest progress at most every kTick, and wakes the clients whose throttle allows an update.
//
// Lifetime: construct before the PrinterService whose hooks call it (with_push), attach() once the
// printers exist, stop() before they are destroyed. The HTTP server closes the sockets on stop.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "server/api/push_channel.hpp"
#include "server/api/push_sockjs.hpp"
#include "server/http/websocket_channel.hpp"
#include "server/printers/printer_service.hpp"
#include "server/store/store.hpp"

namespace salient::server {

class Sessions;
struct OctoState;

class PushHub : public PushFeed {
 public:
  static constexpr std::size_t kMaxLogs = 300;  // terminal lines kept (OctoPrint's terminal keeps 300)
  static constexpr std::size_t kMaxTempsPerUpdate = 300;  // samples in one `current` at most
  static constexpr std::chrono::milliseconds kTick{100};

  // `log`: one line, for what should not happen (the thread's work threw).
  PushHub(Sessions& sessions, Store& store, OctoState& octo, std::function<void(const std::string&)> log = {},
          PushLimits limits = {});
  ~PushHub() override;
  PushHub(const PushHub&) = delete;
  PushHub& operator=(const PushHub&) = delete;

  void attach(PrinterService& printers);  // starts the thread
  void stop();                            // joins it; idempotent

  // The acceptor for HttpServerOptions::websockets["/sockjs/websocket"]: open to anyone (as
  // OctoPrint's: a client gets nothing but `connected` until it authenticates).
  WebSocketAcceptor acceptor();
  // The same behind SockJS's framing, for HttpServerOptions::websockets["/sockjs/*"]
  // (/sockjs/{server}/{session}/websocket; any other path under /sockjs/ is 404).
  WebSocketAcceptor sockjs_acceptor();
  // What the printers' hooks add for the push socket (chained after `events`' own).
  PrinterEvents hooks(PrinterEvents events);

  std::size_t clients() const;

  // PushFeed.
  std::optional<std::string> user_of_auth(std::string_view auth) const override;
  std::string history(PushCursor& cursor, const PushSubscription& subscription) const override;
  std::string backlog(PushCursor& cursor, const PushSubscription& subscription) const override;

 private:
  void run();
  void turn(bool state, bool progress, const std::vector<std::string>& files);  // one of run()'s
  void changed(const Printer& printer, bool progress);
  void terminal(const Printer& printer, bool sent, std::string_view line);
  void files_changed(const std::string& added);
  std::vector<std::shared_ptr<PushChannel>> live_channels();
  void heartbeats();  // wakes the SockJS clients that have been silent too long
  void publish_state_changes(Printer& printer, const std::vector<std::shared_ptr<PushChannel>>& channels);
  bool publish_progress(Printer& printer, const std::vector<std::shared_ptr<PushChannel>>& channels);
  std::shared_ptr<const std::string> current_part(Printer& printer, const PrinterStatus& status);
  std::string temps_json(PushCursor& cursor, std::size_t limit) const;
  std::string logs_json(PushCursor& cursor, bool wanted) const;
  bool is_watched(const Printer& printer) const;

  Sessions& sessions_;
  Store& store_;
  OctoState& octo_;
  std::function<void(const std::string&)> log_;
  PushLimits limits_;
  std::string connected_;
  std::atomic<PrinterService*> printers_{nullptr};
  std::atomic<bool> logs_wanted_{false};

  // The thread's work, under mutex_.
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::thread thread_;
  bool stopping_ = false, state_pending_ = false, progress_pending_ = false;
  std::vector<std::string> files_pending_;  // FileAdded paths ("" for a change without one)

  // The thread's own: the last state told, where the printer's changes were read up to, and the
  // files looked up for the job (forgotten when files change).
  PrinterStatus told_;
  std::uint64_t changes_seen_ = 0;
  std::map<std::string, std::optional<StoredFile>> files_;
  std::chrono::steady_clock::time_point last_recheck_{};
  std::uint64_t rechecked_closes_ = 0;  // sessions_.closes() when the channels were last rechecked

  mutable std::mutex data_mutex_;              // latest_, logs_
  std::shared_ptr<const std::string> latest_;  // the printer's part of the newest `current`
  std::deque<std::pair<std::uint64_t, std::string>> logs_;
  std::uint64_t logs_end_ = 0;

  mutable std::mutex channels_mutex_;
  std::vector<std::weak_ptr<PushChannel>> channels_;
  // SockJS clients' framing (for heartbeats), beside their PushChannel (to wake them by).
  std::vector<std::pair<std::weak_ptr<SockJsChannel>, std::weak_ptr<PushChannel>>> sockjs_;
};

}  // namespace salient::server
