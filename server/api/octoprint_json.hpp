// OctoPrint's documents, shared by its REST routes and its push socket: files with their
// gcodeAnalysis, the printer's state text and flags, temperatures. Included from .cpp files only.
#pragma once

#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>

#include "server/http/http_message.hpp"
#include "server/printers/printer_service.hpp"
#include "server/store/store.hpp"

namespace salient::server {

// What OctoPrint keeps between requests: the selected file, and the analyses of stored files by
// digest (content-addressed, so never stale; bounded, as files come and go).
struct OctoState {
  static constexpr std::size_t kMaxAnalyses = 1024;
  std::mutex mutex;
  std::string selected;
  std::map<std::string, nlohmann::json> analyses;
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

}  // namespace salient::server
