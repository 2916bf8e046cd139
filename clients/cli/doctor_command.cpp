// `salient doctor`: runs the checks (doctor_serial.cpp, doctor_daemon.cpp), prints one line each
// with its fix, and exits 1 when any failed.
#include <sys/statvfs.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>

#include "clients/cli/commands.hpp"
#include "clients/cli/doctor.hpp"

namespace salient::cli {
namespace doctor {

std::string find_data_dir(const std::string& option) {
  if (!option.empty()) return option;
  std::error_code ec;
  for (const char* candidate : {"/var/lib/salient", "var"})
    if (std::filesystem::is_directory(candidate, ec)) return candidate;
  return {};
}

Check disk_check(const std::string& option) {
  const std::string dir = find_data_dir(option);
  if (dir.empty())
    return {Verdict::warn, "disk", "no data directory found (/var/lib/salient, ./var)",
            "--data DIR names it"};
  struct statvfs s {};
  if (::statvfs(dir.c_str(), &s) != 0)
    return {Verdict::fail, "disk", dir + ": cannot be read",
            "check that it exists and this user may read it"};
  const double free_bytes = double(s.f_bavail) * double(s.f_frsize);
  const double total = double(s.f_blocks) * double(s.f_frsize);
  const double share = total > 0 ? free_bytes / total : 0;
  char found[160];
  std::snprintf(found, sizeof found, "%s: %.0f MB free (%.0f %%)", dir.c_str(), free_bytes / 1e6,
                share * 100);
  // Uploads of up to max_upload_mb (64 MB by default) and their G-code must fit.
  if (free_bytes < 200e6 || share < 0.02)
    return {Verdict::fail, "disk", found,
            "free space: delete old jobs and files (the web page), or a bigger disk"};
  if (free_bytes < 1e9 || share < 0.10)
    return {Verdict::warn, "disk", found, "space is getting low: delete old jobs and files"};
  return {Verdict::ok, "disk", found, ""};
}

}  // namespace doctor

namespace {

const char* label(doctor::Verdict v) {
  switch (v) {
    case doctor::Verdict::ok:
      return "ok  ";
    case doctor::Verdict::warn:
      return "warn";
    case doctor::Verdict::fail:
      return "FAIL";
  }
  return "?";
}

int run_doctor(const doctor::Options& o) {
  std::vector<doctor::Check> checks = doctor::serial_checks(o.devices);
  const auto interference = doctor::interference_checks();
  checks.insert(checks.end(), interference.begin(), interference.end());
  checks.push_back(doctor::disk_check(o.data_dir));
  const auto daemon = doctor::daemon_checks(o);
  checks.insert(checks.end(), daemon.begin(), daemon.end());
  bool failed = false;
  for (const doctor::Check& c : checks) {
    std::printf("%s  %-14s %s%s%s\n", label(c.verdict), c.name.c_str(), c.found.c_str(),
                c.fix.empty() ? "" : " — fix: ", c.fix.c_str());
    failed = failed || c.verdict == doctor::Verdict::fail;
  }
  std::fflush(stdout);
  return failed ? 1 : 0;
}

}  // namespace

void add_doctor_command(CLI::App& app, CommandAction& action) {
  auto options = std::make_shared<doctor::Options>();
  CLI::App* cmd = app.add_subcommand(
      "doctor",
      "Why does it not connect? Checks serial devices, permissions, interfering services, the daemon, "
      "the key, the printers, disk space and the clock; one line each with a fix (exit 1: a check failed)");
  cmd->add_option("--server", options->server,
                  "salientd's URL (default: $SALIENT_SERVER or http://127.0.0.1:8080)");
  cmd->add_option("--key", options->key,
                  "API key (default: $SALIENT_API_KEY, else the data directory's api-key file)");
  cmd->add_option("--device", options->devices,
                  "A printer's device path to check too (e.g. its port in the config)");
  cmd->add_option("--data", options->data_dir,
                  "salientd's data directory, for the disk check (default: /var/lib/salient or ./var)");
  cmd->callback([&action, options] { action = [options] { return run_doctor(*options); }; });
}

}  // namespace salient::cli
