// Agents and obstacles as CSV (DESIGN.md §9): the input of `crowddb query`.
//   agents:    id,x,y,vx,vy,radius[,charge]     ids: distinct non-negative integers
//   obstacles: x,y,radius[,charge]              named o<row> (0-based row) in outputs
// Every error is one line naming the file, line and field. Numbers must be finite.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "crowddb/query.hpp"

namespace crowddb::io {

DiscTable read_agents_csv(const std::filesystem::path& path);
std::vector<CircleObstacle> read_obstacles_csv(const std::filesystem::path& path);

// The same over text in memory; `name` stands for the file in messages.
DiscTable parse_agents_csv(std::string_view text, const std::string& name);
std::vector<CircleObstacle> parse_obstacles_csv(std::string_view text, const std::string& name);

// Parses a whole field as a finite double, or throws Error(input) with `where` prefixed.
double parse_number(const char* text, const std::string& where);

}  // namespace crowddb::io
