// Text from a file reaches the terminal (docs/limits.md): names, units and the source file name
// of an import keep their control characters only as \xNN, so an escape sequence in a CSV header
// or a file name cannot recolour or rewrite the terminal; printable_text leaves other text
// (UTF-8 included) unchanged.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "diag/io/import.hpp"
#include "diag/io/printable.hpp"

namespace fs = std::filesystem;

TEST(ImportPrintable, ControlCharactersAreEscaped) {
  EXPECT_EQ(diag::printable_text("acc \xc2\xb5m/s^2 \xe2\x80\x94 ok"),
            "acc \xc2\xb5m/s^2 \xe2\x80\x94 ok");
  EXPECT_EQ(diag::printable_text("a\x1b[31mb\x7f"), "a\\x1b[31mb\\x7f");
  EXPECT_EQ(diag::printable_text("c1 \xc2\x9b"
                                 "2J"),
            "c1 \\xc2\\x9b2J");  // C1 CSI in UTF-8
  EXPECT_FALSE(diag::has_control_characters("plain text"));
  EXPECT_TRUE(diag::has_control_characters("tab\there"));
}

TEST(ImportPrintable, CsvNamesAndSourceReachNoTerminalRaw) {
  const fs::path dir = geardiag_test::scratch_dir("import_printable");
  const fs::path path = dir / "name\x1b]0;title\x07.csv";
  {
    std::ofstream out(path);
    out << "time,acc\x1b[2J\n";
    for (int i = 0; i < 20; ++i) out << i * 0.001 << "," << (i % 3) << "\n";
  }
  const diag::Recording rec = diag::import_recording(path);
  ASSERT_EQ(rec.signals.size(), 1u);
  EXPECT_EQ(rec.signals[0].name, "acc\\x1b[2J");
  EXPECT_EQ(rec.metadata.at("source"), "name\\x1b]0;title\\x07.csv");
  fs::remove_all(dir);
}
