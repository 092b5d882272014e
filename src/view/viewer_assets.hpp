// The viewer's page (viewer/, bundled by esbuild at build time), embedded in the binary by
// cmake/embed_assets.cmake. Built with -DCROWDDB_BUILD_VIEWER=OFF, kEmbedded is false and the
// arrays are empty.
#pragma once

#include <cstddef>

namespace crowddb::view::assets {

extern const bool kEmbedded;
extern const unsigned char kIndexHtml[], kAppJs[], kAppCss[];
extern const std::size_t kIndexHtmlSize, kAppJsSize, kAppCssSize;

}  // namespace crowddb::view::assets
