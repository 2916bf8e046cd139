#include "server/api/push_hub.hpp"

#include <algorithm>
#include <limits>
#include <nlohmann/json.hpp>

#include "server/api/api_json.hpp"
#include "server/api/octoprint_json.hpp"
#include "server/api/push_event.hpp"
#include "server/api/sessions.hpp"
#include "server/build_info.hpp"
#include "server/common/json_text.hpp"
#include "server/store/print_store.hpp"
#include "server/store/sha256.hpp"

namespace salient::server {

using nlohmann::json;

namespace {

constexpr std::size_t kMaxLogLine = 512;  // bytes of one terminal line told

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// OctoPrint's {"connected": …}: its version (the one /api/server tells), hashes that change when
// ours does (clients reload their UI on a change), and the permissions it knows.
std::string connected_message() {
  const std::string hash = sha256_hex("salient " + std::string(version())).substr(0, 32);
  json permissions = json::array();
  for (const char* key : {"ADMIN", "STATUS", "CONNECTION", "CONTROL", "FILES_LIST", "FILES_UPLOAD",
                          "FILES_DOWNLOAD", "FILES_DELETE", "FILES_SELECT", "PRINT", "SETTINGS_READ"})
    permissions.push_back({{"key", key}, {"name", key}, {"needs", {{"role", {key}}}}});
  return json_text(json{{"connected",
                         {{"version", kOctoPrintVersion},
                          {"display_version", kOctoPrintVersion},
                          {"branch", nullptr},
                          {"python_version", nullptr},
                          {"plugin_hash", hash},
                          {"config_hash", hash},
                          {"debug", false},
                          {"safe_mode", false},
                          {"online", true},
                          {"wizard", false},
                          {"permissions", permissions}}}});
}

}  // namespace

PushHub::PushHub(Sessions& sessions, Store& store, OctoState& octo,
                 std::function<void(const std::string&)> log, PushLimits limits)
    : sessions_(sessions),
      store_(store),
      octo_(octo),
      log_(std::move(log)),
      limits_(limits),
      connected_(connected_message()) {
  octo_.on_files_changed = [this](const std::string& added) { files_changed(added); };
}

PushHub::~PushHub() {
  stop();
  octo_.on_files_changed = nullptr;
}

void PushHub::attach(PrinterService& printers) {
  printers_ = &printers;
  if (Printer* p = printers.first()) latest_ = current_part(*p, told_);
  thread_ = std::thread([this] { run(); });
}

void PushHub::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

WebSocketAcceptor PushHub::acceptor() {
  return [this](const HttpRequest&) -> WebSocketAccept {
    auto channel = std::make_shared<PushChannel>(*this, connected_, limits_);
    std::lock_guard lock(channels_mutex_);
    std::erase_if(channels_, [](const auto& w) { return w.expired(); });
    channels_.push_back(channel);
    return {channel, {}};
  };
}

WebSocketAcceptor PushHub::sockjs_acceptor() {
  return [this](const HttpRequest& r) -> WebSocketAccept {
    if (!is_sockjs_websocket_path(r.path))
      return {nullptr, error_response(
                           404, "not_found",
                           "no SockJS endpoint at " + r.path + ": use /sockjs/{server}/{session}/websocket")};
    auto channel = std::make_shared<PushChannel>(*this, connected_, limits_);
    auto framed = std::make_shared<SockJsChannel>(channel);
    std::lock_guard lock(channels_mutex_);
    std::erase_if(channels_, [](const auto& w) { return w.expired(); });
    std::erase_if(sockjs_, [](const auto& w) { return w.first.expired(); });
    channels_.push_back(channel);
    sockjs_.emplace_back(framed, channel);
    return {framed, {}};
  };
}

PrinterEvents PushHub::hooks(PrinterEvents events) {
  events.changed = [this, first = std::move(events.changed)](const Printer& p, bool progress) {
    if (first) first(p, progress);
    changed(p, progress);
  };
  events.terminal_wanted = [this, first = std::move(events.terminal_wanted)](const Printer& p) {
    return (first && first(p)) || (logs_wanted_ && is_watched(p));
  };
  events.terminal = [this, first = std::move(events.terminal)](const Printer& p, bool sent,
                                                               std::string_view line) {
    if (first) first(p, sent, line);
    terminal(p, sent, line);
  };
  return events;
}

std::size_t PushHub::clients() const {
  std::lock_guard lock(channels_mutex_);
  return static_cast<std::size_t>(
      std::count_if(channels_.begin(), channels_.end(), [](const auto& w) { return !w.expired(); }));
}

bool PushHub::is_watched(const Printer& printer) const {
  PrinterService* printers = printers_;
  return printers && printers->first() == &printer;
}

void PushHub::changed(const Printer& printer, bool progress) {
  if (!is_watched(printer)) return;
  {
    std::lock_guard lock(mutex_);
    (progress ? progress_pending_ : state_pending_) = true;
  }
  if (!progress) wake_.notify_all();  // a change of state goes out at once; progress on the tick
}

void PushHub::terminal(const Printer& printer, bool sent, std::string_view line) {
  if (!logs_wanted_ || !is_watched(printer)) return;
  std::string text = sent ? "Send: " : "Recv: ";
  text.append(line.substr(0, kMaxLogLine));
  std::lock_guard lock(data_mutex_);
  logs_.emplace_back(++logs_end_, std::move(text));
  if (logs_.size() > kMaxLogs) logs_.pop_front();
}

void PushHub::files_changed(const std::string& added) {
  {
    std::lock_guard lock(mutex_);
    if (files_pending_.size() < 64) files_pending_.push_back(added);
  }
  wake_.notify_all();
}

std::vector<std::shared_ptr<PushChannel>> PushHub::live_channels() {
  std::vector<std::shared_ptr<PushChannel>> out;
  std::lock_guard lock(channels_mutex_);
  std::erase_if(channels_, [](const auto& w) { return w.expired(); });
  for (const auto& w : channels_)
    if (auto c = w.lock()) out.push_back(std::move(c));
  return out;
}

void PushHub::run() {
  for (;;) {
    std::vector<std::string> files;
    bool state = false, progress = false;
    {
      std::unique_lock lock(mutex_);
      wake_.wait_for(lock, kTick, [&] { return stopping_ || state_pending_ || !files_pending_.empty(); });
      if (stopping_) return;
      state = std::exchange(state_pending_, false);
      progress = std::exchange(progress_pending_, false);
      files.swap(files_pending_);
    }
    try {
      turn(state, progress, files);
    } catch (const std::exception& e) {  // a bug: logged, and the clients are served on
      if (log_) log_(std::string("push socket internal error: ") + e.what());
    }
  }
}

void PushHub::turn(bool state, bool progress, const std::vector<std::string>& files) {
  const auto channels = live_channels();
  Printer* printer = printers_.load()->first();
  if (!files.empty()) files_.clear();  // sizes and dates may have changed
  if (printer && (state || progress)) {
    publish_state_changes(*printer, channels);
    if (progress && !publish_progress(*printer, channels)) {
      std::lock_guard lock(mutex_);
      progress_pending_ = true;  // a change of state came first: it is told, then this
    }
  }
  for (const std::string& added : files) {
    for (const auto& c : channels) {
      if (!added.empty())
        c->event("FileAdded", json_text(json{{"storage", "local"},
                                             {"path", added},
                                             {"name", added.substr(added.find_last_of('/') + 1)},
                                             {"type", {"machinecode", "gcode"}}}));
      c->event("UpdatedFiles", R"({"type":"printables"})");
    }
  }
  // Sessions that ended (a revoked key, here or on another node) lose their clients' updates: looked
  // at once a second at most, and only after this node closed some, so that the hub's thread asks
  // the database nothing while none did.
  const std::uint64_t closes = sessions_.closes();
  const bool recheck = closes != rechecked_closes_ &&
                       std::chrono::steady_clock::now() - last_recheck_ >= std::chrono::seconds(1);
  if (recheck) last_recheck_ = std::chrono::steady_clock::now();
  bool logs = false, checked = true;
  for (const auto& c : channels) {
    if (recheck) checked = c->recheck_session() && checked;
    logs = logs || c->wants_logs();
    if (c->due()) c->wake();
  }
  if (recheck && checked) rechecked_closes_ = closes;  // else again in a second
  logs_wanted_ = logs;
  heartbeats();
}

void PushHub::heartbeats() {
  std::vector<std::pair<std::shared_ptr<SockJsChannel>, std::shared_ptr<PushChannel>>> due;
  {
    std::lock_guard lock(channels_mutex_);
    std::erase_if(sockjs_, [](const auto& w) { return w.first.expired(); });
    for (const auto& [framed, channel] : sockjs_)
      if (auto f = framed.lock(); f && f->heartbeat_due())
        if (auto c = channel.lock()) due.emplace_back(std::move(f), std::move(c));
  }
  for (const auto& [framed, channel] : due) channel->wake();
}

void PushHub::publish_state_changes(Printer& printer,
                                    const std::vector<std::shared_ptr<PushChannel>>& channels) {
  for (const PrinterStatus& s : printer.state_changes_since(changes_seen_)) {
    auto part = current_part(printer, s);
    const std::vector<PushEvent> events = push_events(told_, s);
    told_ = s;
    {
      std::lock_guard lock(data_mutex_);
      latest_ = part;
    }
    for (const auto& c : channels) {
      c->state_changed(part);
      for (const PushEvent& e : events) c->event(e.type, e.payload);
    }
  }
}

bool PushHub::publish_progress(Printer& printer, const std::vector<std::shared_ptr<PushChannel>>& channels) {
  const PrinterStatus s = printer.status();
  // A state not told yet: its own `current` goes first (next turn), never overtaken by this one.
  if (s.state != told_.state || s.error != told_.error) return false;
  auto part = current_part(printer, s);
  {
    std::lock_guard lock(data_mutex_);
    latest_ = part;
  }
  for (const auto& c : channels) c->progress(part);
  return true;
}

// The printer's part of `current`: state, job, progress, currentZ, offsets, resends, busyFiles.
std::shared_ptr<const std::string> PushHub::current_part(Printer& printer, const PrinterStatus& s) {
  std::string selected;
  json offsets = json::object();
  {
    std::lock_guard lock(octo_.mutex);
    selected = octo_.selected;
    for (const auto& [name, value] : octo_.offsets) offsets[name] = value;
  }
  const std::string name = s.print ? s.print->record.filename : selected;
  std::optional<StoredFile> file;
  json analysis = nullptr;
  if (!name.empty()) {
    auto it = files_.find(name);
    if (it == files_.end()) {
      if (files_.size() >= 64) files_.clear();
      it = files_.emplace(name, PrintStore(store_.db()).file(name)).first;
    }
    file = it->second;
    if (file && printers_.load()) {
      const json f = file_json_analysed(*file, HttpRequest{}, store_, *printers_.load(), octo_);
      if (const auto a = f.find("gcodeAnalysis"); a != f.end()) analysis = *a;
    }
  }
  const PrinterCounters n = printer.counters();
  json busy = json::array();
  if (busy_printing(s.state) && s.print)
    busy.push_back({{"origin", "local"}, {"path", name}, {"name", name}});
  const json part = {
      {"state", state_json(s)},
      {"job", print_job_json(s, selected, file, analysis)},
      {"progress", progress_json(s)},
      {"currentZ", s.print && s.print->z ? json(*s.print->z) : json(nullptr)},
      {"offsets", offsets},
      {"resends",
       {{"count", n.lines_resent},
        {"transmitted", n.lines_sent},
        {"ratio", n.lines_sent > 0 ? static_cast<int>(100 * n.lines_resent / n.lines_sent) : 0}}},
      {"busyFiles", busy}};
  return std::make_shared<const std::string>(json_text(part));
}

std::optional<std::string> PushHub::user_of_auth(std::string_view auth) const {
  return sessions_.user_of_auth(auth);
}

std::string PushHub::temps_json(PushCursor& cursor, std::size_t limit) const {
  PrinterService* printers = printers_;
  std::string out = "[";
  if (!printers || !printers->first()) return out + "]";
  const double now = now_seconds();
  std::vector<TemperatureSample> all = printers->temperatures(printers->first()->id()).samples(now);
  std::erase_if(all, [](const TemperatureSample& t) { return !has_reading(t); });
  auto from =
      std::find_if(all.begin(), all.end(), [&](const auto& t) { return t.time > cursor.temps_after; });
  if (static_cast<std::size_t>(all.end() - from) > limit)
    from = all.end() - static_cast<std::ptrdiff_t>(limit);
  for (auto it = from; it != all.end(); ++it) {
    if (out.size() > 1) out += ',';
    out += json_text(temperature_sample_json(*it));
    cursor.temps_after = it->time;
  }
  return out + "]";
}

std::string PushHub::logs_json(PushCursor& cursor, bool wanted) const {
  json lines = json::array();
  std::lock_guard lock(data_mutex_);
  for (const auto& [seq, line] : logs_)
    if (seq > cursor.logs_after && wanted) lines.push_back(line);
  cursor.logs_after = logs_end_;
  return json_text(lines);
}

std::string PushHub::history(PushCursor& cursor, const PushSubscription& subscription) const {
  std::shared_ptr<const std::string> part;
  {
    std::lock_guard lock(data_mutex_);
    part = latest_;
  }
  std::string out = part && part->size() > 2 ? part->substr(0, part->size() - 1) + "," : std::string("{");
  cursor = PushCursor{};  // the whole half hour, and every line kept
  out += "\"temps\":" + temps_json(cursor, std::numeric_limits<std::size_t>::max());
  out += ",\"logs\":" + logs_json(cursor, subscription.logs);
  out += ",\"messages\":[],\"serverTime\":" + json_text(json(now_seconds())) + "}";
  return out;
}

std::string PushHub::backlog(PushCursor& cursor, const PushSubscription& subscription) const {
  std::string out = "\"temps\":" + temps_json(cursor, kMaxTempsPerUpdate);
  out += ",\"logs\":" + logs_json(cursor, subscription.logs);
  out += ",\"messages\":[],\"serverTime\":" + json_text(json(now_seconds()));
  return out;
}

}  // namespace salient::server
