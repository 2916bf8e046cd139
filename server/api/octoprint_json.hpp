// OctoPrint's documents, shared by its REST routes and its push socket: files with their
// gcodeAnalysis, the printer's state text and flags, temperatures. Included from .cpp files only.
#pragma once

#include <functional>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "server/http/http_message.hpp"
#include "server/printers/printer_service.hpp"
#include "server/printers/temperature_history.hpp"
#include "server/store/store.hpp"

namespace salient::server {

// What OctoPrint keeps between requests: the selected file, and the analyses of stored files by
// digest (content-addressed, so never stale; bounded, as files come and go).
struct OctoState {
  static constexpr std::size_t kMaxAnalyses = 1024;
  std::mutex mutex;
  std::string selected;
  std::map<std::string, nlohmann::json> analyses;
  // Set once before serving: told when the routes add (`added`: its path) or change files (the
  // push socket's FileAdded and UpdatedFiles events). Call files_changed(), not this.
  std::function<void(const std::string& added)> on_files_changed;
  void files_changed(const std::string& added = {}) const {
    if (on_files_changed) on_files_changed(added);
  }
  // Temperature offsets set through /api/printer/tool|bed ("tool0", "bed"), °C, reported with
  // the temperatures and added to the targets set through the API.
  std::map<std::string, double> offsets;
};

bool is_gcode(const std::string& name);
// The printer OctoPrint's API drives: the first configured (409 when there is none).
Printer& default_printer(PrinterService& printers);
// "http://HOST" from the request's Host header; empty without one.
std::string base_url(const HttpRequest& r);
nlohmann::json file_json(const StoredFile& f, const HttpRequest& r);
// file_json with the file's gcodeAnalysis, computed once per content.
nlohmann::json file_json_analysed(const StoredFile& f, const HttpRequest& r, Store& store,
                                  PrinterService& printers, OctoState& octo);
// The OctoPrint version we answer as (/api/server, /api/version, the push socket's "connected").
inline constexpr const char* kOctoPrintVersion = "1.10.0";

// "Operational", "Printing", "Finishing", "Cancelling", "Error: …", "Offline"…
std::string state_text(const PrinterStatus& s);
// OctoPrint's state ids (PrinterStateChanged's state_id): "OPERATIONAL", "PRINTING", "FINISHING"…
std::string state_id(const PrinterStatus& s);
// {text, flags{operational, printing, paused, cancelling, finishing, …}, error}. As OctoPrint's
// comm.py: `printing` is true while the print is streaming, cancelling or finishing.
nlohmann::json state_json(const PrinterStatus& s);
// {tool0{actual, target, offset}, bed{…}}
nlohmann::json temperature_json(const PrinterStatus& s);
// One entry of the push socket's `temps`: {time (s, whole), tool0{actual, target}, bed{…}}.
nlohmann::json temperature_sample_json(const TemperatureSample& sample);
// Whether a sample holds a reading: OctoPrint's histories have none without (our page's chart
// keeps those as its gaps: a printer connecting or disconnected).
bool has_reading(const TemperatureSample& sample);
// The job document (GET /api/job's and the push socket's `job`): the print under way, or else the
// selected file (`file`: its row when stored; `analysis`: its gcodeAnalysis, or null).
nlohmann::json print_job_json(const PrinterStatus& s, const std::string& selected,
                              const std::optional<StoredFile>& file, const nlohmann::json& analysis);
// The progress document: completion (0–100), filepos (bytes of the file), printTime,
// printTimeLeft (s), printTimeLeftOrigin; all null between prints.
nlohmann::json progress_json(const PrinterStatus& s);
// The same with the offsets set through the API.
nlohmann::json temperature_json(const PrinterStatus& s, const std::map<std::string, double>& offsets);
// OctoPrint's temperature history: the last `limit` samples with a reading, oldest first, as
// [{time (s), tool0{actual, target}, bed{actual, target}}].
nlohmann::json temperature_history_json(const std::vector<TemperatureSample>& samples, std::size_t limit);
// A folder as OctoPrint lists it: {name, display, path, type: "folder", typePath, origin, refs}.
nlohmann::json folder_json(const std::string& path, const HttpRequest& r);

}  // namespace salient::server
