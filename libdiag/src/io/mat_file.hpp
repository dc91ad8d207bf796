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
// objects) are skipped by their byte count, unread, whatever dimensions they declare (a sparse
// matrix of 10^5 x 10^5 holds only its non-zeros); a sparse matrix is named in a note. Level 7.3
// files are HDF5 (is_mat73(), read by mat73.cpp). A level 4 file is held in memory once; a level
// 5 file is read element by element (an element's bytes in memory once), or frame by frame
// (level5_frames).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "diag/io/recording.hpp"
#include "diag/io/recording_frames.hpp"

namespace diag::mat {

struct Variable {
  std::string name;
  std::vector<std::size_t> dims;
  std::vector<double> values;  // column-major
  bool integer_class = false;  // int8 ... uint64 (prints as an integer)
  std::string exact_text;      // a 64-bit integer scalar's exact value ("" otherwise)
  bool described = false;      // values not read, only the dimensions (mat73_frames: the
                               // samples are read frame by frame)
};

// True when the file is a MATLAB 7.3 .mat file (HDF5 with a MATLAB header).
bool is_mat73(const std::filesystem::path& path);

// Decodes every real numeric variable of a level 4 or 5 file. Throws InputError naming `where`,
// the variable and the damage. Notes on skipped variables go to `notes` when given.
std::vector<Variable> read_numeric_variables(const std::filesystem::path& path,
                                             const std::string& where, std::uint64_t file_size,
                                             std::vector<std::string>* notes = nullptr);

// Decodes every real numeric variable of a level 7.3 file (HDF5), through the project's one HDF5
// open (hdf5_file.hpp) and the crash guard. Throws InputError naming the file and the variable.
std::vector<Variable> read_mat73_variables(const std::filesystem::path& path,
                                           std::vector<std::string>* notes = nullptr);

// What a MAT file read frame by frame hands out (level5_frames, mat73_frames): the recording its
// variables make, without samples, as every measured format's (named after its file, printable,
// roles unstated); each frame reads every channel's span (read_span) and refuses a NaN or
// infinite sample, naming the variable and the sample.
class VariableFrames : public FrameSource {
 public:
  std::vector<ChannelExtent> extents() const override;
  Recording frame(double t0_s, double t1_s) const override;

 protected:
  // `rec` as Assemble made it, its channels named after their variables; `length(i, signal)`:
  // the samples of channel i.
  void set_recording(Recording rec, const std::filesystem::path& path, const std::string& where,
                     const std::function<std::uint64_t(std::size_t, const Signal&)>& length);
  // Samples [first, first + out.size()) of channel i's variable.
  virtual void read_span(std::size_t i, std::uint64_t first, std::span<double> out) const = 0;
  const std::string& where() const { return where_; }
  const std::string& variable(std::size_t i) const { return channels_[i].variable; }

 private:
  struct Channel {
    std::string variable;  // the signal's name before it was made printable
    std::uint64_t length = 0;
    double fs_hz = 0;
  };
  std::string where_;
  Recording recording_;
  std::vector<Channel> channels_;
};

// A level 7.3 file frame by frame: its variables surveyed once (the crash guard's child reads
// every value; this process only the scalars' and every variable's dimensions), `assemble`
// makes the recording from them (its vector channels without samples, named after their
// variables, at their rate), and each frame reads those vectors' samples by blocks. A frame
// with a NaN or infinite sample is refused naming the variable and the sample's index.
using Assemble =
    std::function<Recording(std::vector<Variable>& variables, std::vector<std::string>& notes)>;
std::shared_ptr<const FrameSource> mat73_frames(const std::filesystem::path& path,
                                                const Assemble& assemble);

// A level 5 file frame by frame: the file surveyed once by its elements' tags and headers
// (scalars and vectors of up to 64 KiB decoded whole, as read_numeric_variables does; larger
// vectors only described), and each frame reads those vectors' values at their offsets, or, in a
// compressed element, inflates its stream forward from the previous frame's end (frames read in
// order inflate each element once). Memory holds a frame, not the file. Null for a level 4 file
// (read whole). Throws InputError as read_numeric_variables, a frame for its damage or a NaN.
std::shared_ptr<const FrameSource> level5_frames(const std::filesystem::path& path,
                                                 const std::string& where, std::uint64_t file_size,
                                                 const Assemble& assemble);

}  // namespace diag::mat
