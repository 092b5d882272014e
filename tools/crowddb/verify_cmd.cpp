// `crowddb verify`: the verification suite of src/verify/ under one model or all of them.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "cli_checks.hpp"
#include "commands.hpp"
#include "crowddb/error.hpp"
#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "io/overrides.hpp"
#include "steer/model.hpp"
#include "verify/verify.hpp"

namespace crowddb::cli {
namespace {

struct VerifyOptions {
  std::string model;
  std::vector<std::string> cases;
  std::vector<std::string> overrides;
  std::string csv, write_dir;
  int threads = 1;
  bool list = false, quiet = false;
};

std::string limits(const verify::Check& c) {
  const bool lo = std::isfinite(c.low), hi = std::isfinite(c.high);
  char buf[64];
  if (lo && hi && c.low == c.high)
    std::snprintf(buf, sizeof buf, "= %g", c.low);
  else if (lo && hi)
    std::snprintf(buf, sizeof buf, "in [%g, %g]", c.low, c.high);
  else if (lo)
    std::snprintf(buf, sizeof buf, ">= %g", c.low);
  else if (hi)
    std::snprintf(buf, sizeof buf, "<= %g", c.high);
  else
    std::snprintf(buf, sizeof buf, "(reported)");
  return buf;
}

int verify_run(const VerifyOptions& o) {
  std::vector<const verify::Case*> chosen;
  std::set<std::string> names(o.cases.begin(), o.cases.end());
  for (const verify::Case& c : verify::cases())
    if (names.empty() || names.count(c.name)) chosen.push_back(&c);
  for (const std::string& n : names) {
    bool found = false;
    for (const verify::Case* c : chosen) found = found || c->name == n;
    if (!found) {
      std::string all;
      for (const verify::Case& c : verify::cases()) all += (all.empty() ? "" : ", ") + c.name;
      throw Error(Error::Kind::usage, "--case: unknown case '" + n + "' (choose from " + all + ")");
    }
  }
  if (o.list) {
    for (const verify::Case* c : chosen)
      std::cout << c->name << "  [" << c->family << "]  " << c->what << "\n";
    return 0;
  }
  if (!o.write_dir.empty()) {
    std::filesystem::create_directories(o.write_dir);
    for (const verify::Case* c : chosen)
      for (std::size_t k = 0; k < c->scenarios.size(); ++k) {
        const std::string path = o.write_dir + "/" + c->name +
                                 (c->scenarios.size() > 1 ? "-" + std::to_string(k + 1) : "") +
                                 ".json";
        write_output(path, c->scenarios[k] + "\n");
      }
    std::cout << "wrote the scenarios of " << chosen.size() << " cases to " << o.write_dir << "\n";
    return 0;
  }
  if (!o.overrides.empty() && !chosen.empty()) {
    // A malformed or invalid --set is the command's error, before any case runs.
    nlohmann::json doc = nlohmann::json::parse(chosen.front()->scenarios.front());
    io::apply_overrides(doc, o.overrides);
    parse_scenario(doc.dump(), "--set");
  }
  std::vector<std::string> models;
  if (o.model == "all") {
    for (const auto& m : steer::model_registry()) models.push_back(m.name);
  } else {
    models.push_back(o.model.empty() ? SimConfig{}.steering.model : o.model);
    steer::find_model(models.back());  // usage error for an unknown name
  }
  std::ostringstream csv;
  csv << "model,case,family,check,value,low,high,pass\n";
  std::vector<std::vector<bool>> passed(models.size());
  for (std::size_t mi = 0; mi < models.size(); ++mi) {
    const std::string& model = models[mi];
    std::cout << "crowddb verify: model " << model << ", " << chosen.size() << " cases\n";
    std::size_t ok = 0;
    for (const verify::Case* c : chosen) {
      if (!o.quiet) std::cerr << "  running " << c->name << " ...\r" << std::flush;
      const verify::CaseResult r = verify::run_case(*c, model, o.threads, o.overrides);
      passed[mi].push_back(r.pass());
      ok += r.pass();
      char head[200];
      std::snprintf(head, sizeof head, "  %-24s %-4s %6.1f s  %s\n", c->name.c_str(),
                    r.pass() ? "pass" : "FAIL", r.wall_seconds, c->family.c_str());
      std::cout << head;
      for (const verify::Check& k : r.checks) {
        char line[200];
        std::snprintf(line, sizeof line, "      %-4s %-44s %12.4g  %s\n", k.pass() ? "" : "FAIL",
                      k.name.c_str(), k.value, limits(k).c_str());
        std::cout << line;
        csv << model << "," << c->name << ",\"" << c->family << "\",\"" << k.name << "\","
            << format_number(k.value) << "," << format_number(k.low) << "," << format_number(k.high)
            << "," << (k.pass() ? 1 : 0) << "\n";
      }
    }
    std::cout << "  " << ok << " of " << chosen.size() << " cases pass under " << model << "\n\n";
  }
  if (models.size() > 1) {
    std::cout << "case                      ";
    for (const std::string& m : models) std::printf("%-8s", m.c_str());
    std::cout << std::flush;
    std::printf("\n");
    for (std::size_t k = 0; k < chosen.size(); ++k) {
      std::printf("%-26s", chosen[k]->name.c_str());
      for (std::size_t mi = 0; mi < models.size(); ++mi)
        std::printf("%-8s", passed[mi][k] ? "pass" : "FAIL");
      std::printf("\n");
    }
    std::fflush(stdout);
  }
  if (!o.csv.empty()) write_output(o.csv, csv.str());
  bool all = true;
  for (const auto& p : passed)
    for (bool b : p) all = all && b;
  return all ? 0 : 3;
}

}  // namespace

void add_verify_command(CLI::App& app, Action& action) {
  static VerifyOptions o;
  auto* sub = app.add_subcommand(
      "verify",
      "run the verification suite (RiMEA and SteerSuite-style cases with pass criteria); exit "
      "status 3 when a case fails");
  sub->add_option("--model", o.model,
                  "steering model to verify, or 'all' (default: the default model)");
  add_set_option(sub, o.overrides);
  sub->add_option("--case", o.cases, "run only this case (repeatable; --list shows them)");
  sub->add_option("--csv", o.csv, "also write every check as CSV to this file");
  sub->add_option("--threads", o.threads, "threads (results do not depend on it)")
      ->check(cli_checks::whole(1, 256));
  sub->add_option("--write", o.write_dir,
                  "write each case's scenario files into this folder instead of running them");
  sub->add_flag("--list", o.list, "list the cases and exit");
  sub->add_flag("--quiet", o.quiet, "no progress line");
  sub->callback([&action] { action = [] { return verify_run(o); }; });
}

}  // namespace crowddb::cli
