// --set KEY=VALUE overrides of a scenario document: paths, values, errors; and a crowddb file
// loaded with them.
#include "io/overrides.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "crowddb/error.hpp"
#include "crowddb/scenario.hpp"

namespace crowddb::io {
namespace {

using nlohmann::json;

TEST(Overrides, SetNestedFieldsCreatingObjectsAndIndexingArrays) {
  json doc = json::parse(R"({"steering": {"model": "orca"}, "groups": [{"count": 5}]})");
  apply_overrides(doc, {"steering.orca.time_gap=0.5", "steering.model=cfsm", "groups.0.count=7",
                        "name=\"a b\"", "seed=[1, 2]", "duration=1e3"});
  EXPECT_EQ(doc["steering"]["orca"]["time_gap"], 0.5);
  EXPECT_EQ(doc["steering"]["model"], "cfsm");  // not JSON: a string
  EXPECT_EQ(doc["groups"][0]["count"], 7);
  EXPECT_EQ(doc["name"], "a b");
  EXPECT_EQ(doc["seed"], json::parse("[1, 2]"));  // the reader rejects it, naming /seed
  EXPECT_EQ(doc["duration"], 1000.0);
}

TEST(Overrides, LaterOverridesWin) {
  json doc = json::object();
  apply_overrides(doc, {"seed=1", "seed=2"});
  EXPECT_EQ(doc["seed"], 2);
}

TEST(Overrides, MalformedOverridesNameThemselves) {
  const char* cases[][2] = {
      {"steering.orca", "--set 'steering.orca': expected KEY=VALUE"},
      {"=3", "--set '=3': expected KEY=VALUE"},
      {"steering..x=1", "empty key segment"},
      {"name.x=1", "'name' is not an object"},
      {"groups.x=1", "'x' indexes an array"},
      {"groups.4.count=1", "index 4 is past the array's end (1 elements)"},
      {"name=\xC3(", "not valid UTF-8"},
  };
  for (const auto& [item, message] : cases) {
    json doc = json::parse(R"({"name": "n", "groups": [{"count": 5}]})");
    try {
      apply_overrides(doc, {item});
      ADD_FAILURE() << item;
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), Error::Kind::usage);
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

// A file written to a fresh folder, removed with it.
class TempFile {
 public:
  explicit TempFile(const std::string& text) {
    char tmpl[] = "/tmp/crowddb-overrides-XXXXXX";
    dir_ = mkdtemp(tmpl);
    path_ = dir_ / "scenario.json";
    std::ofstream(path_, std::ios::binary) << text;
  }
  ~TempFile() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path dir_, path_;
};

std::string load_error(const std::filesystem::path& path, std::vector<std::string> overrides) {
  try {
    load_scenario(path, LoadOptions{{}, std::move(overrides)});
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::input);
    return e.what();
  }
  return "";
}

// The overrides are applied before the document is checked (docs/scenario-format.md): a file
// whose group its region cannot hold loads once --set makes the group smaller, and a value set
// wrong is named as the file's error would be. The file's own JSON is still read strictly: a
// syntax error keeps its line and column, a duplicate key stays an error.
TEST(Overrides, AppliedBeforeTheFileIsChecked) {
  const TempFile crowded(R"({"bounds": [0, 0, 3, 3], "goals": [{"name": "g", "x": 2, "y": 2}],
    "groups": [{"count": 400, "placement": {"type": "uniform", "region": [0, 0, 3, 3]},
                "goal": "g"}]})");
  EXPECT_NE(load_error(crowded.path(), {}).find("/groups/0/placement: could not place agent"),
            std::string::npos);
  const Scenario sc = load_scenario(crowded.path(), LoadOptions{{}, {"groups.0.count=5"}});
  EXPECT_EQ(sc.world.agents().size(), 5u);
  const Converted c = convert_scenario(crowded.path(), LoadOptions{{}, {"groups.0.count=5"}});
  EXPECT_EQ(nlohmann::json::parse(c.json)["groups"][0]["count"], 5);
  EXPECT_THROW(convert_scenario(crowded.path(), LoadOptions{}), Error);  // invalid as it stands

  EXPECT_NE(load_error(crowded.path(), {"groups.0.count=5", "dt=-1"}).find("/dt"),
            std::string::npos);

  const TempFile twice(R"({"bounds": [0, 0, 3, 3], "dt": 0.1, "dt": 0.2,
    "goals": [{"name": "g", "x": 2, "y": 2}], "agents": [{"x": 1, "y": 1, "goal": "g"}]})");
  EXPECT_NE(load_error(twice.path(), {"seed=3"}).find("duplicate key \"dt\""), std::string::npos);

  const TempFile broken("{\"bounds\": [0, 0, 3, 3],\n  \"dt\": 0.1,,\n}");
  const std::string e = load_error(broken.path(), {"seed=3"});
  EXPECT_NE(e.find("scenario.json:2:"), std::string::npos) << e;
  EXPECT_NE(e.find("malformed JSON"), std::string::npos) << e;
}

}  // namespace
}  // namespace crowddb::io
