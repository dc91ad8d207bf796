// MATLAB .mat files, levels 4 and 5 (MATLAB's -v4, -v6 and -v7 formats), decoded here rather
// than by matio: every size a header declares is checked against the bytes actually present
// before anything is allocated or read, so a truncated or corrupted file is refused naming the
// variable and what is wrong, never imported as zeros, garbage or uninitialised memory. The
// layout follows "MAT-File Format", The MathWorks, R2018a (mat-file-format.pdf): a 128-byte
// header, then data elements (8-byte tag: type and byte count, or the 4-byte "small element"
// form); variables are miMATRIX elements (array flags, dimensions, name, real part, imaginary
// part), or miCOMPRESSED elements holding one zlib-compressed miMATRIX. Level 4: a 20-byte
// header (type MOPT, rows, columns, imaginary flag, name length) per variable, then the name and
// the column-major data.
//
// Only what an import uses is decoded: real, non-logical numeric arrays (any numeric class,
// stored in any numeric type). Other variables (char, cell, struct, sparse, complex, logical,
// objects) are skipped by their byte count, unread. Level 7.3 files are HDF5 (is_mat73()).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace diag::mat {

struct Variable {
  std::string name;
  std::vector<std::size_t> dims;
  std::vector<double> values;  // column-major
  bool integer_class = false;  // int8 ... uint64 (prints as an integer)
  std::string exact_text;      // a 64-bit integer scalar's exact value ("" otherwise)
};

// True when the file is a MATLAB 7.3 .mat file (HDF5 with a MATLAB header).
bool is_mat73(const std::filesystem::path& path);

// Decodes every real numeric variable of a level 4 or 5 file. Throws InputError naming `where`,
// the variable and the damage.
std::vector<Variable> read_numeric_variables(const std::filesystem::path& path,
                                             const std::string& where, std::uint64_t file_size);

}  // namespace diag::mat
