// Printers and prints as API JSON: the one place a PrinterStatus or a PrintRecord becomes the
// document that GET /api/v1/printers/{id} returns and "printer" events carry.
#pragma once

#include <nlohmann/json.hpp>

#include "server/printers/printer_status.hpp"
#include "server/store/print_store.hpp"
#include "server/store/queue_store.hpp"

namespace salient::server {

// id, job, file, state, confirmed, total, progress, reason, started_at, finished_at, resumable.
nlohmann::json print_record_json(const PrintRecord& p);
// id, kind, protocol, profile, state, error, firmware, device, temperatures, print (with
// elapsed and eta), last_print.
nlohmann::json printer_status_json(const PrinterStatus& s);
// A printer's queue: {"printer", "entries": [{entry, position, state: "queued", job | file,
// queued_at}]}, what GET …/queue returns and "queue" events carry.
nlohmann::json print_queue_json(const std::string& printer_id, const std::vector<QueueEntry>& entries);

}  // namespace salient::server
