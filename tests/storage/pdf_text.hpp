// A PDF's text as poppler's pdftotext reads it back (an independent reader of
// what Cairo wrote); `layout` keeps the page's columns on one line.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/test_data.hpp"

namespace bodyscan::testing {

inline std::string pdf_text(const std::string& pdf, bool layout = false) {
  const std::string dir = temp_dir();
  { std::ofstream(dir + "/doc.pdf", std::ios::binary) << pdf; }
  const std::string cmd =
      std::string("pdftotext ") + (layout ? "-layout " : "") + dir + "/doc.pdf " + dir + "/doc.txt 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << "pdftotext (poppler-utils) reads the PDF back";
  std::ifstream in(dir + "/doc.txt");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace bodyscan::testing
