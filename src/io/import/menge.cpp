#include "io/import/menge.hpp"

#include "crowddb/error.hpp"

namespace crowddb::io {

Imported import_menge(const std::filesystem::path& path, std::string_view, const LoadOptions&) {
  throw Error(Error::Kind::input, path.string() + ": Menge files are not supported yet");
}

}  // namespace crowddb::io
