// The importers, how a file's format is recognised, and the loading entry points that dispatch on
// it (load_scenario, convert_scenario, scenario_format).
#include <cctype>
#include <nlohmann/json.hpp>
#include <sstream>

#include "crowddb/error.hpp"
#include "io/import/importer.hpp"
#include "io/import/menge.hpp"
#include "io/import/steersuite.hpp"
#include "io/import/vadere.hpp"
#include "io/overrides.hpp"
#include "util/read_file.hpp"

namespace crowddb::io {
namespace {

bool has_extension(const std::filesystem::path& path, std::string_view ext) {
  std::string e = path.extension().string();
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e == ext;
}

bool steersuite_claims(const std::filesystem::path&, std::string_view head) {
  const std::string root = xml_root_name(head);
  return root == "SteerBenchTestCase" || root == "SteerSuiteSubSpace";
}

bool menge_claims(const std::filesystem::path&, std::string_view head) {
  const std::string root = xml_root_name(head);
  return root == "Project" || root == "Experiment" || root == "BFSM";
}

bool vadere_claims(const std::filesystem::path& path, std::string_view head) {
  if (has_extension(path, ".scenario")) return true;
  // A Vadere file saved as .json: its topography sits under "scenario" (or "vadere" before 0.2).
  return head.find("\"topography\"") != std::string_view::npos &&
         head.find("\"release\"") != std::string_view::npos;
}

const Importer kImporters[] = {
    {"steersuite", "SteerSuite test cases (<SteerBenchTestCase> XML)", steersuite_claims,
     import_steersuite},
    {"menge", "Menge projects, scene and behaviour XML (<Project>, <Experiment>, <BFSM>)",
     menge_claims, import_menge},
    {"vadere", "Vadere .scenario files (JSON, releases 0.1 to 2.4)", vadere_claims, import_vadere},
};

// A file no importer claims is read as crowddb JSON; an XML one gets an error naming its root.
void reject_unknown_xml(const std::filesystem::path& path, std::string_view text) {
  std::size_t i = text.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
  while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
  if (i >= text.size() || text[i] != '<') return;
  const std::string root = xml_root_name(text);
  throw Error(Error::Kind::input,
              path.string() + ": an XML file with root <" + root +
                  "> is not a format crowddb reads (SteerSuite <SteerBenchTestCase>, Menge "
                  "<Project>, <Experiment> or <BFSM>; docs/importers.md)");
}

// A crowddb file's text with the options' overrides applied. The file's own JSON is read
// strictly first (a syntax error keeps its line and column, a duplicate key is caught: the
// re-written document has neither); the rest is checked after the overrides, by whoever loads
// the result, so that --set can mend a value the file has wrong (a group too large for its
// region) as docs/scenario-format.md says.
std::string with_overrides(const std::filesystem::path& path, const std::string& text,
                           const LoadOptions& options) {
  if (options.overrides.empty()) return text;
  nlohmann::json doc = io::parse_json_strict(text, path.string());
  apply_overrides(doc, options.overrides);
  return doc.dump(2) + "\n";
}

}  // namespace

std::span<const Importer> importers() {
  return kImporters;
}

const Importer* importer_for(const std::filesystem::path& path, std::string_view head) {
  for (const Importer& imp : kImporters)
    if (imp.claims(path, head)) return &imp;
  return nullptr;
}

std::string xml_root_name(std::string_view t) {
  std::size_t i = 0;
  if (t.substr(0, 3) == "\xEF\xBB\xBF") i = 3;  // UTF-8 byte order mark
  while (i < t.size()) {
    while (i < t.size() && (t[i] == ' ' || t[i] == '\t' || t[i] == '\n' || t[i] == '\r')) ++i;
    if (i >= t.size() || t[i] != '<') return "";
    if (t.substr(i, 4) == "<!--") {
      const auto end = t.find("-->", i + 4);
      if (end == std::string_view::npos) return "";
      i = end + 3;
    } else if (t.substr(i, 2) == "<?" || t.substr(i, 2) == "<!") {
      const auto end = t.find('>', i + 2);
      if (end == std::string_view::npos) return "";
      i = end + 1;
    } else {
      std::size_t j = i + 1;
      while (j < t.size() && t[j] != ' ' && t[j] != '>' && t[j] != '/' && t[j] != '\t' &&
             t[j] != '\n' && t[j] != '\r')
        ++j;
      std::string name(t.substr(i + 1, j - i - 1));
      const auto colon = name.find(':');
      return colon == std::string::npos ? name : name.substr(colon + 1);
    }
  }
  return "";
}

std::string read_file(const std::filesystem::path& path) {
  return read_input_file(path);
}

}  // namespace crowddb::io

namespace crowddb {

std::string scenario_format(const std::filesystem::path& path) {
  const std::string text = io::read_file(path);
  const io::Importer* imp = io::importer_for(path, text);
  return imp ? imp->name : "crowddb";
}

Scenario load_scenario(const std::filesystem::path& path, const LoadOptions& options) {
  const std::string text = io::read_file(path);
  const io::Importer* imp = io::importer_for(path, text);
  if (!imp) {
    io::reject_unknown_xml(path, text);
    if (!options.behavior.empty())
      throw Error(Error::Kind::usage,
                  path.string() + ": a behaviour file goes with a Menge scene, not with a " +
                      "crowddb scenario");
    if (options.overrides.empty()) return parse_scenario(text, path.string());
    return parse_scenario(io::with_overrides(path, text, options), path.string());
  }
  io::Imported im = imp->read(path, text, options);
  io::apply_overrides(im.doc, options.overrides);
  Scenario sc = io::parse_document(im.doc.dump(2) + "\n", path.string(), &im.origins);
  sc.format = imp->name;
  sc.warnings.insert(sc.warnings.begin(), im.warnings.begin(), im.warnings.end());
  return sc;
}

Converted convert_scenario(const std::filesystem::path& path, const LoadOptions& options) {
  const std::string text = io::read_file(path);
  const io::Importer* imp = io::importer_for(path, text);
  if (!imp) {
    io::reject_unknown_xml(path, text);
    // A crowddb file converts to itself (with the overrides), if it is valid.
    const std::string json = io::with_overrides(path, text, options);
    parse_scenario(json, path.string());
    return {json, "crowddb", {}};
  }
  io::Imported im = imp->read(path, text, options);
  io::apply_overrides(im.doc, options.overrides);
  Converted c{im.doc.dump(2) + "\n", imp->name, std::move(im.warnings)};
  // Check that it loads, so that a converted file is never one that fails to run.
  io::parse_document(c.json, path.string(), &im.origins);
  return c;
}

}  // namespace crowddb
