// Ground-truth files told by content: a TUM trajectory and a relations file both hold 8 numbers
// a line, so the extension and the option a file came under do not say which one it is.
// std only.
#pragma once

#include <cstddef>
#include <string>

namespace kfd {

enum class GroundTruthFormat {
    Tum,        // "t x y z qx qy qz qw" (readTum)
    Relations,  // "t1 t2 x y z roll pitch yaw" (readRelations)
    Unknown,    // no data line, or the content fits both or neither
};
/// "a TUM trajectory (t x y z qx qy qz qw)", "a relations file (t1 t2 x y z roll pitch yaw)",
/// "neither clearly a TUM trajectory nor a relations file".
const char* toString(GroundTruthFormat f);

/// What detectGroundTruthFormat() saw: the format and the row counts it was decided on.
struct GroundTruthGuess {
    GroundTruthFormat format = GroundTruthFormat::Unknown;
    std::size_t rows = 0;          // data lines of 8 numbers (the first kMaxRows)
    std::size_t later_stamp = 0;   // column 2 > column 1: a later stamp (relations' t2)
    std::size_t shared_stamp = 0;  // column 2 equal (1e-6) to some row's column 1 (relations)
    std::size_t zero_5_to_7 = 0;   // columns 5-7 zero (relations' z, roll, pitch)
    std::size_t zero_4_to_6 = 0;   // columns 4-6 zero (a planar TUM's z, qx, qy)
    std::size_t unit_quat = 0;     // columns 5-8 of norm 1 +- 1e-3 (a TUM quaternion)
    /// "2978 of 2984 rows have a later stamp in column 2, 2959 one of column 1's, ..."
    std::string evidence() const;
    static constexpr std::size_t kMaxRows = 100000;
};

/// Tells a TUM trajectory from a relations file by content (blank lines, '#' comments and
/// lines that are not 8 numbers are ignored here; the readers reject them). A relations file
/// (Kümmerle et al. 2009) has z, roll and pitch 0 and a second stamp in column 2: later than
/// column 1 and, in the benchmark's files, most often another row's first stamp. A TUM file's
/// column 2 is x; a planar trajectory has z, qx and qy 0 and most files a unit quaternion
/// (the TUM reader also accepts any non-zero norm). At least 90 % of the rows must show one
/// format's signature (relations: columns 5-7 zero and column 2 a later or a shared stamp;
/// TUM: columns 4-6 zero or a unit quaternion) and not the other's; a file that shows both is
/// TUM when 90 % of its rows hold a unit quaternion (a toy trajectory along x with yaw 0),
/// else Unknown, like a file that shows neither. Throws EvalError "ground truth not found: PATH"
/// when `path` is not a regular file, or when it cannot be opened.
GroundTruthGuess detectGroundTruthFormat(const std::string& path);

}  // namespace kfd
