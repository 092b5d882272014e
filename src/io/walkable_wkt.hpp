#pragma once

#include <string>

#include "crowddb/world.hpp"

namespace crowddb::io {

// The walkable area as WKT (JuPedSim's `geometry` table): the bounds minus every obstacle,
// circles as 64-gons. A POLYGON with holes, or a MULTIPOLYGON when obstacles cut the area apart.
// Computed with Boost.Geometry, so overlapping obstacles still give valid geometry.
std::string walkable_area_wkt(const World& world);

}  // namespace crowddb::io
