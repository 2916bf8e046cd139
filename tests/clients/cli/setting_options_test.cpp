// The settings table against every place a setting appears: the CLI's plan and slice options, a
// job's JSON and its canonical form, and the README's list.
#include "clients/cli/setting_options.hpp"

#include <doctest/doctest.h>

#include <CLI/CLI.hpp>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>

#include "clients/cli/commands.hpp"
#include "core/common/input_error.hpp"
#include "server/common/domain_error.hpp"
#include "server/jobs/job_settings.hpp"

using namespace salient;
using nlohmann::json;

namespace {

// The options of plan and slice that are not settings: the input, the outputs and help.
const std::set<std::string> not_settings = {"MODEL", "--json", "--output", "--svg", "--help"};

// Exactly these settings are not job settings (the table says why).
const std::set<core::SettingId> cli_only = {core::SettingId::saliency_file};

// For each setting a value other than its default, as a job sends it and as typed after the flag.
const std::map<core::SettingId, std::pair<json, std::string>>& samples() {
  using I = core::SettingId;
  static const std::map<I, std::pair<json, std::string>> s = {
      {I::printer, {"ender3", "ender3"}},
      {I::planner, {"cusp", "cusp"}},
      {I::up, {"0,-1,0.2", "0,-1,0.2"}},
      {I::height, {40.0, "40"}},
      {I::scale, {2.5, "2.5"}},
      {I::min_layer, {0.05, "0.05"}},
      {I::max_layer, {0.25, "0.25"}},
      {I::grid, {0.05, "0.05"}},
      {I::rho, {0.1, "0.1"}},
      {I::layers, {50, "50"}},
      {I::layer_height, {0.2, "0.2"}},
      {I::metric, {"paper", "paper"}},
      {I::objective, {"layers", "layers"}},
      {I::saliency, {"painted", "painted"}},
      {I::saliency_file, {"values.txt", "values.txt"}},
      {I::seed, {7, "7"}},
      {I::segment, {true, ""}},
      {I::segment_depth, {2, "2"}},
      {I::segment_planes, {3, "3"}},
      {I::walls, {3, "3"}},
      {I::infill, {0.5, "0.5"}},
      {I::line_width, {0.5, "0.5"}},
      {I::top_thickness, {1.2, "1.2"}},
      {I::bottom_thickness, {1.2, "1.2"}},
      {I::combine_infill, {false, "false"}},
      {I::support, {true, ""}},
      {I::support_angle, {40.0, "40"}},
  };
  return s;
}

// A job's settings that give `s` its sample (and what it needs to apply).
json job_with(const core::Setting& s) {
  json j = {{std::string(s.key), samples().at(s.id).first}};
  if (s.only_with) j[std::string(core::setting_key(*s.only_with))] = true;
  if (s.id == core::SettingId::layer_height) j["planner"] = "uniform";
  return j;
}

core::Settings of(const server::JobSettings& job) {
  return core::Settings{job.printer, job.slice};
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST_CASE("the table is in SettingId's order and its keys are the name table's") {
  const auto& table = core::setting_table();
  REQUIRE(table.size() == samples().size());
  for (std::size_t i = 0; i < table.size(); ++i) {
    CAPTURE(table[i].key);
    CHECK(static_cast<std::size_t>(table[i].id) == i);
    CHECK(core::setting_key(table[i].id) == table[i].key);
    CHECK(core::setting_by_key(table[i].key) == &table[i]);
    CHECK(bool(table[i].get));
    CHECK(bool(table[i].set));
    CHECK((table[i].type == core::SettingType::choice) == (table[i].choices != nullptr));
  }
}

TEST_CASE("every setting is an option of plan or slice, and every planning option of theirs is a setting") {
  CLI::App app;
  cli::CommandAction action;
  cli::add_plan_command(app, action);
  cli::add_slice_command(app, action);
  const std::map<unsigned, CLI::App*> commands = {{core::for_plan, app.get_subcommand("plan")},
                                                  {core::for_slice, app.get_subcommand("slice")}};
  for (const core::Setting& s : core::setting_table()) {
    CAPTURE(s.key);
    CHECK((s.commands & (core::for_plan | core::for_slice)) != 0);
    for (const auto& [bit, command] : commands) {
      const CLI::Option* option = command->get_option_no_throw(std::string(s.flag));
      CHECK((option != nullptr) == ((s.commands & bit) != 0));
    }
  }
  for (const auto& [bit, command] : commands)
    for (const CLI::Option* option : command->get_options()) {
      const std::string name = option->get_name();
      CAPTURE(name);
      if (not_settings.count(name)) continue;
      bool found = false;
      for (const core::Setting& s : core::setting_table()) found |= s.flag == name && (s.commands & bit);
      CHECK(found);
    }
  // slice takes the layer limits from the printer unless given, and says so.
  const CLI::Option* max_layer = commands.at(core::for_slice)->get_option("--max-layer");
  CHECK(max_layer->get_default_str().empty());
  CHECK(max_layer->get_description().find("printer profile") != std::string::npos);
  CHECK(commands.at(core::for_plan)->get_option("--max-layer")->get_default_str() == "0.4");
}

TEST_CASE(
    "every setting but the CLI-only ones is a job setting that round-trips through the canonical form") {
  std::set<core::SettingId> refused;
  for (const core::Setting& s : core::setting_table()) {
    CAPTURE(s.key);
    const json job = job_with(s);
    if (!s.not_a_job_setting.empty()) {
      refused.insert(s.id);
      CHECK_THROWS_AS(server::parse_job_settings(job.dump()), server::BadRequest);
      continue;
    }
    const server::JobSettings parsed = server::parse_job_settings(job.dump());
    const std::optional<core::SettingValue> given = s.get(of(parsed));
    REQUIRE(given);
    CHECK(given != s.get(core::Settings{}));  // the sample is not the default (nor unset)
    CHECK(parsed.canonical.find("\"" + std::string(s.key) + "\":") != std::string::npos);
    const server::JobSettings again = server::parse_job_settings(parsed.canonical);
    CHECK(again.canonical == parsed.canonical);
    CHECK(s.get(of(again)) == given);
  }
  CHECK(refused == cli_only);
  // Defaults leave the settings added later out of the canonical form: older jobs keep theirs.
  const std::string plain = server::parse_job_settings("").canonical;
  for (const char* key : {"segment", "segment_planes", "line_width", "combine_infill", "min_layer"})
    CHECK(plain.find(key) == std::string::npos);
}

TEST_CASE("the CLI sets what a job's JSON sets") {
  for (const core::Setting& s : core::setting_table()) {
    CAPTURE(s.key);
    CLI::App app;
    const cli::SettingOptions options(app, core::for_plan | core::for_slice);
    std::vector<std::string> args = {std::string(s.flag)};
    if (!samples().at(s.id).second.empty()) args.push_back(samples().at(s.id).second);
    std::reverse(args.begin(), args.end());  // CLI11 takes them last first
    app.parse(args);
    core::Settings cli;
    options.apply(cli);
    core::Settings job;
    s.set(job, s.type == core::SettingType::number
                   ? core::SettingValue(samples().at(s.id).first.get<double>())
               : s.type == core::SettingType::integer
                   ? core::SettingValue(samples().at(s.id).first.get<std::int64_t>())
               : s.type == core::SettingType::flag
                   ? core::SettingValue(samples().at(s.id).first.get<bool>())
                   : core::SettingValue(samples().at(s.id).first.get<std::string>()));
    CHECK(s.get(cli) == s.get(job));
  }
}

TEST_CASE("the README lists the table") {
  const std::string readme = read_file(std::string(SALIENT_SOURCE_DIR) + "/README.md");
  const std::size_t begin = readme.find("<!-- settings table: begin");
  const std::size_t end = readme.find("<!-- settings table: end -->");
  REQUIRE(begin != std::string::npos);
  REQUIRE(end != std::string::npos);
  const std::size_t first = readme.find('\n', begin) + 1;
  CHECK(readme.substr(first, end - first) == core::settings_markdown());
}

TEST_CASE("core names settings by id: the CLI spells them as flags and a job as quoted keys") {
  const core::InputError e(core::SettingId::grid, "0.03 mm does not divide {min_layer} 0.1 {nothing}");
  CHECK(std::string(e.what()) == "grid: 0.03 mm does not divide min_layer 0.1 {nothing}");
  CHECK(e.spelled(cli::cli_flag) == "--grid: 0.03 mm does not divide --min-layer 0.1 {nothing}");
  try {
    server::parse_job_settings(R"({"grid": 0.03})");
    FAIL("refused");
  } catch (const server::BadRequest& b) {
    CHECK(std::string(b.what()).find("'grid'") != std::string::npos);
    CHECK(std::string(b.what()).find("--") == std::string::npos);
  }
}
