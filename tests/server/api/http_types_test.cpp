#include "server/api/http_types.hpp"

#include <gtest/gtest.h>

namespace bodyscan::server {
namespace {

TEST(FileResponse, SavesUnderItsNameAndIsCachedNowhere) {
  const HttpResponse r = file_response("%PDF-1.5", "application/pdf", "scan-1-measurements.pdf");
  EXPECT_EQ(r.status, 200);
  EXPECT_EQ(r.body, "%PDF-1.5");
  EXPECT_EQ(r.get("Content-Type"), "application/pdf");
  EXPECT_EQ(r.get("Content-Disposition"), "attachment; filename=\"scan-1-measurements.pdf\"");
  EXPECT_EQ(r.get("Cache-Control"), "private, no-store");
  EXPECT_EQ(file_response("", "application/pdf", "a.pdf", "inline").get("Content-Disposition"),
            "inline; filename=\"a.pdf\"");
}

TEST(FileResponse, ANameCannotEndTheHeaderOrItsQuotes) {
  const HttpResponse r = file_response("x", "text/csv", "a\"b\\c\r\nSet-Cookie: x=1\x7f.csv");
  EXPECT_EQ(r.get("Content-Disposition"), "attachment; filename=\"abcSet-Cookie: x=1.csv\"");
}

}  // namespace
}  // namespace bodyscan::server
