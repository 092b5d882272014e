#include "io/import/vadere.hpp"

#include "crowddb/error.hpp"

namespace crowddb::io {

Imported import_vadere(const std::filesystem::path& path, std::string_view, const LoadOptions&) {
  throw Error(Error::Kind::input, path.string() + ": Vadere files are not supported yet");
}

}  // namespace crowddb::io
