// OctoPrint's documents, shared by its REST routes and its push socket: files with their
// gcodeAnalysis, the printer's state text and flags, temperatures. Included from .cpp files only.
#pragma once

#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
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
// "Operational", "Printing", "Error: …", "Offline"…
std::string state_text(const PrinterStatus& s);
// {text, flags{operational, printing, paused, …}}
nlohmann::json state_json(const PrinterStatus& s);
// {tool0{actual, target, offset}, bed{…}}
nlohmann::json temperature_json(const PrinterStatus& s);
// The same with the offsets set through the API.
nlohmann::json temperature_json(const PrinterStatus& s, const std::map<std::string, double>& offsets);
// OctoPrint's temperature history: the last `limit` samples, oldest first, as
// [{time (s), tool0{actual, target}, bed{actual, target}}].
nlohmann::json temperature_history_json(const std::vector<TemperatureSample>& samples, std::size_t limit);
// A folder as OctoPrint lists it: {name, display, path, type: "folder", typePath, origin, refs}.
nlohmann::json folder_json(const std::string& path, const HttpRequest& r);

}  // namespace salient::server
