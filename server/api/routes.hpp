// The daemon's endpoints, declared in one place per area.
#pragma once

#include "server/config/daemon_config.hpp"
#include "server/http/router.hpp"
#include "server/jobs/job_service.hpp"
#include "server/store/store.hpp"

namespace salient::server {

// /healthz, /api/version (open).
void add_system_routes(Router& router);
// /api/v1/jobs…: submit, list, get, cancel/remove, artefacts.
void add_job_routes(Router& router, Store& store, JobService& jobs, const DaemonConfig& config);

}  // namespace salient::server
