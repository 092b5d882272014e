// The streaming SDF3 reader against the document-tree reader on 50,000 mutated texts (label
// slow; 1,500 in io_test.cpp).
#include "sdf3_reader_checks.hpp"

namespace sdf {
namespace {

TEST(Sdf3ReaderSlow, StreamingReaderAgreesWithTheDocumentReader) {
  test::streaming_reader_agrees(74, 50000);
}

}  // namespace
}  // namespace sdf
