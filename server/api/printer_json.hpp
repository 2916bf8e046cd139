// Printers and prints as API JSON: the one place a PrinterStatus or a PrintRecord becomes the
// document that GET /api/v1/printers/{id} returns and "printer" events carry.
#pragma once

#include <nlohmann/json.hpp>

#include "server/printers/printer_status.hpp"
#include "server/store/farm_store.hpp"
#include "server/store/print_store.hpp"
#include "server/store/queue_store.hpp"

namespace salient::server {

// id, job, file, state, confirmed, total, progress, reason, started_at, finished_at, filament_mm,
// paused_seconds, duration, print_duration (null until ended), resumable.
nlohmann::json print_record_json(const PrintRecord& p);
// A history's sums: prints, finished, cancelled, failed, interrupted, total_seconds,
// print_seconds, filament_mm, longest_seconds, longest_print_seconds.
nlohmann::json print_totals_json(const PrintTotals& t);
// id, kind, protocol, profile, state, error, firmware, device, temperatures, print (with
// elapsed and eta), last_print.
nlohmann::json printer_status_json(const PrinterStatus& s);
// Another farm node's printer as that node last wrote it (with its node), "offline" unless `live`.
nlohmann::json farm_printer_json(const FarmPrinter& p, bool live);
// A queue: {"printer" (or "profile" for a farm-wide queue), "entries": [{entry, position,
// state: "queued" or "slicing" (a job not sliced yet), job | file, queued_at}]}, what
// GET …/queue returns and "queue" events carry. `key`: a printer id or "profile/P".
nlohmann::json print_queue_json(const std::string& key, const std::vector<QueueEntry>& entries);

}  // namespace salient::server
