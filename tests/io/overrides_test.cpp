// --set KEY=VALUE overrides of a scenario document: paths, values, errors.
#include "io/overrides.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "crowddb/error.hpp"

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

}  // namespace
}  // namespace crowddb::io
