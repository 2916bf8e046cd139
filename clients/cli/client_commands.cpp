// The client commands, over a running salientd: `salient submit MODEL --wait`, `salient jobs`,
// `salient watch JOB`, `salient printers`, `salient send PRINTER M105`. Progress comes from the
// WebSocket, not from polling.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "clients/cli/commands.hpp"
#include "clients/cli/daemon_client.hpp"
#include "core/common/input_error.hpp"
#include "server/jobs/job_state.hpp"

namespace salient::cli {
namespace {

using nlohmann::json;

struct ClientOptions {
  std::string server, key;
  bool json = false;
};

void add_client_options(CLI::App& cmd, ClientOptions& o) {
  cmd.add_option("--server", o.server, "salientd's URL (default: $SALIENT_SERVER or http://127.0.0.1:8080)");
  cmd.add_option("--key", o.key, "API key (default: $SALIENT_API_KEY or var/api-key)");
  cmd.add_flag("--json", o.json, "Print the daemon's JSON instead of text");
}

std::string read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw core::InputError(path, {}, "cannot read");
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

// The job's state in the daemon's JSON, by the daemon's own name table; empty for a name this
// salient does not know (a newer daemon's).
std::optional<server::JobState> state_of(const json& job) {
  return server::job_state_from(job.value("state", ""));
}

// One line about a job: "j3f…  running  saliency  42%" or the result when done.
std::string describe_job(const json& j) {
  std::string line = j.value("id", "") + "  " + j.value("state", "") + "  " + j.value("filename", "");
  const auto state = state_of(j);
  if (state == server::JobState::running || state == server::JobState::queued)
    line += "  " + j.value("phase", "") + " " + fixed(100 * j.value("progress", 0.0), 0) + "%";
  if (state == server::JobState::done && j.contains("result")) {
    const json& r = j["result"];
    line += "  " + std::to_string(r.value("layers", 0)) + " layers (finest " +
            std::to_string(r.value("finest_layers", 0)) + ", " + fixed(100 * r.value("saving", 0.0), 1) +
            "% fewer), print " + fixed(r.value("print_seconds", 0.0) / 60, 1) + " min";
  }
  if (state == server::JobState::failed && j["error"].is_string())
    line += "  error: " + j["error"].get<std::string>();
  return line;
}

void progress_bar(const json& j) {
  const double p = std::clamp(j.value("progress", 0.0), 0.0, 1.0);
  const int filled = static_cast<int>(p * 30);
  std::fprintf(
      stderr, "\r[%s%s] %3d%% %-10s", std::string(static_cast<std::size_t>(filled), '#').c_str(),
      std::string(static_cast<std::size_t>(30 - filled), ' ').c_str(), static_cast<int>(p * 100),
      state_of(j) == server::JobState::running ? j.value("phase", "").c_str() : j.value("state", "").c_str());
  std::fflush(stderr);
}

// Follows job/ID until it finishes; returns the last job document.
json follow_job(DaemonClient& client, const std::string& id, bool bar, bool json_lines) {
  json last;
  client.watch({"job/" + id}, [&](const std::string& text) {
    const json m = json::parse(text, nullptr, false);
    if (m.is_discarded() || m.value("type", "") != "job") return true;
    last = m["data"];
    if (json_lines)
      std::printf("%s\n", text.c_str()), std::fflush(stdout);
    else if (bar)
      progress_bar(last);
    else
      std::printf("%s\n", describe_job(last).c_str()), std::fflush(stdout);
    const auto state = state_of(last);
    return !(state && server::finished(*state));
  });
  if (bar && !json_lines) std::fprintf(stderr, "\n");
  return last;
}

int exit_status(const json& job) {
  const auto state = state_of(job);
  return state == server::JobState::done ? 0 : state == server::JobState::cancelled ? 130 : 1;
}

template <typename F>
int guarded(F&& f) {
  try {
    return f();
  } catch (const DaemonError& e) {
    std::fprintf(stderr, "salient: error: %s\n", e.what());
    return e.status() == 0 ? 4 : 1;
  }
}

}  // namespace

void add_client_commands(CLI::App& app, CommandAction& action) {
  {
    struct SubmitOptions : ClientOptions {
      std::string model, settings, output, print;
      bool wait = false;
    };
    auto o = std::make_shared<SubmitOptions>();
    CLI::App* cmd = app.add_subcommand("submit", "Send a model to salientd to slice (a job)");
    cmd->add_option("model", o->model, "STL, OBJ, PLY or OFF file")->required()->check(CLI::ExistingFile);
    cmd->add_option("--settings", o->settings,
                    "Job settings as JSON, e.g. '{\"planner\":\"exact\",\"layers\":60}'");
    cmd->add_flag("--wait", o->wait,
                  "Follow the job to the end with a progress bar (exit 0 done, 1 failed, 130 cancelled)");
    cmd->add_option("-o,--output", o->output, "With --wait: save the G-code here");
    cmd->add_option("--print", o->print, "With --wait: then print it on this printer (e.g. sim)");
    add_client_options(*cmd, *o);
    cmd->callback([o, &action] {
      action = [o] {
        return guarded([&] {
          DaemonClient client(resolve_daemon(o->server, o->key));
          std::vector<std::pair<std::string, std::string>> fields;
          if (!o->settings.empty()) fields.emplace_back("settings", o->settings);
          const DaemonReply r =
              client.upload("/api/v1/jobs", "file", std::filesystem::path(o->model).filename().string(),
                            read_file(o->model), fields);
          json job = json::parse(r.body);
          const std::string id = job.value("id", "");
          if (!o->wait) {
            std::printf("%s\n", o->json ? r.body.c_str() : describe_job(job).c_str());
            return 0;
          }
          if (!o->json)
            std::fprintf(stderr, "job %s%s\n", id.c_str(),
                         r.status == 200 ? " (reused: same model and settings)" : "");
          job = follow_job(client, id, true, o->json);
          if (!o->json) std::printf("%s\n", describe_job(job).c_str());
          if (exit_status(job) != 0) return exit_status(job);
          if (!o->output.empty()) {
            const DaemonReply g = client.request("GET", "/api/v1/jobs/" + id + "/gcode");
            std::ofstream(o->output, std::ios::binary) << g.body;
            if (!o->json) std::printf("G-code -> %s\n", o->output.c_str());
          }
          if (!o->print.empty()) {
            client.request("POST", "/api/v1/printers/" + o->print + "/print", json{{"job", id}}.dump());
            if (!o->json) std::printf("printing on %s (salient printers to follow)\n", o->print.c_str());
          }
          return 0;
        });
      };
    });
  }
  {
    struct JobsOptions : ClientOptions {
      std::string state;
      int limit = 20;
    };
    auto o = std::make_shared<JobsOptions>();
    CLI::App* cmd = app.add_subcommand("jobs", "List salientd's jobs, newest first");
    cmd->add_option("--state", o->state, "Only queued, running, done, failed or cancelled");
    cmd->add_option("--limit", o->limit, "How many")->capture_default_str();
    add_client_options(*cmd, *o);
    cmd->callback([o, &action] {
      action = [o] {
        return guarded([&] {
          DaemonClient client(resolve_daemon(o->server, o->key));
          std::string target = "/api/v1/jobs?limit=" + std::to_string(o->limit);
          if (!o->state.empty()) target += "&state=" + o->state;
          const DaemonReply r = client.request("GET", target);
          if (o->json) return std::printf("%s\n", r.body.c_str()), 0;
          const json j = json::parse(r.body);
          for (const json& job : j["jobs"]) std::printf("%s\n", describe_job(job).c_str());
          std::printf("(%lld jobs in all)\n", j.value("total", 0LL));
          return 0;
        });
      };
    });
  }
  {
    struct WatchOptions : ClientOptions {
      std::string job;
    };
    auto o = std::make_shared<WatchOptions>();
    CLI::App* cmd = app.add_subcommand("watch", "Follow a job's phases until it ends (events from salientd)");
    cmd->add_option("job", o->job, "Job id")->required();
    add_client_options(*cmd, *o);
    cmd->callback([o, &action] {
      action = [o] {
        return guarded([&] {
          DaemonClient client(resolve_daemon(o->server, o->key));
          return exit_status(follow_job(client, o->job, false, o->json));
        });
      };
    });
  }
  {
    struct EventsOptions : ClientOptions {
      std::vector<std::string> topics;
    };
    auto o = std::make_shared<EventsOptions>();
    CLI::App* cmd = app.add_subcommand("events", "Print salientd's events as JSON lines until interrupted");
    cmd->add_option("topics", o->topics, "jobs, job/ID, printers, printer/ID, terminal/ID")->required();
    add_client_options(*cmd, *o);
    cmd->callback([o, &action] {
      action = [o] {
        return guarded([&] {
          DaemonClient client(resolve_daemon(o->server, o->key));
          client.watch(o->topics, [](const std::string& text) {
            std::printf("%s\n", text.c_str());
            std::fflush(stdout);
            return true;
          });
          return 0;
        });
      };
    });
  }
  {
    struct SendOptions : ClientOptions {
      std::string printer;
      std::vector<std::string> commands;
      bool force = false;
    };
    auto o = std::make_shared<SendOptions>();
    CLI::App* cmd = app.add_subcommand(
        "send", "Send G-code commands to a printer's console (e.g. salient send sim M105 \"M104 S200\")");
    cmd->add_option("printer", o->printer, "Printer id")->required();
    cmd->add_option("commands", o->commands, "G-code commands, one per argument")->required();
    cmd->add_flag("--force", o->force,
                  "Send moves and homing (G28, G1, …) even while the printer prints: they spoil the print");
    add_client_options(*cmd, *o);
    cmd->callback([o, &action] {
      action = [o] {
        return guarded([&] {
          DaemonClient client(resolve_daemon(o->server, o->key));
          json body = {{"commands", o->commands}};
          if (o->force) body["force"] = true;
          const DaemonReply r =
              client.request("POST", "/api/v1/printers/" + o->printer + "/command", body.dump());
          if (o->json) return std::printf("%s\n", r.body.c_str()), 0;
          std::printf("sent %zu command%s to %s\n", o->commands.size(), o->commands.size() == 1 ? "" : "s",
                      o->printer.c_str());
          return 0;
        });
      };
    });
  }
  {
    auto o = std::make_shared<ClientOptions>();
    CLI::App* cmd =
        app.add_subcommand("printers", "Show salientd's printers: state, temperatures, print progress");
    add_client_options(*cmd, *o);
    cmd->callback([o, &action] {
      action = [o] {
        return guarded([&] {
          DaemonClient client(resolve_daemon(o->server, o->key));
          const DaemonReply r = client.request("GET", "/api/v1/printers");
          if (o->json) return std::printf("%s\n", r.body.c_str()), 0;
          const json all = json::parse(r.body);
          for (const json& p : all["printers"]) {
            std::string line = p.value("id", "") + "  " + p.value("state", "");
            const json& t = p["temperatures"];
            if (t["hotend"]["actual"].is_number())
              line +=
                  "  hotend " + fixed(t["hotend"]["actual"].get<double>(), 1) + "/" +
                  fixed(t["hotend"]["target"].is_number() ? t["hotend"]["target"].get<double>() : 0.0, 0) +
                  "°C";
            if (t["bed"]["actual"].is_number())
              line += "  bed " + fixed(t["bed"]["actual"].get<double>(), 1) + "/" +
                      fixed(t["bed"]["target"].is_number() ? t["bed"]["target"].get<double>() : 0.0, 0) +
                      "°C";
            if (p["print"].is_object())
              line += "  " + p["print"].value("file", "") + " " +
                      fixed(100 * p["print"].value("progress", 0.0), 1) + "%";
            if (p["error"].is_string()) line += "  error: " + p["error"].get<std::string>();
            if (p["last_print"].is_object() && p["last_print"].value("resumable", false))
              line += "  (print " + std::to_string(p["last_print"].value("id", 0LL)) + " was " +
                      p["last_print"].value("state", "") + " at command " +
                      std::to_string(p["last_print"].value("confirmed", 0LL)) +
                      ": resume with POST /api/v1/printers/" + p.value("id", "") +
                      "/print {\"resume\": " + std::to_string(p["last_print"].value("id", 0LL)) + "})";
            std::printf("%s\n", line.c_str());
          }
          return 0;
        });
      };
    });
  }
}

}  // namespace salient::cli
