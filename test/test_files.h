// Scratch files for the tests that read and write logs (std + gtest only).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace kfd {
namespace test {

/// A fresh folder named after the running test (prefix + test name), removed at the end.
struct TempDir {
    std::filesystem::path path;
    explicit TempDir(const std::string& prefix) {
        path = std::filesystem::temp_directory_path() /
               (prefix + ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::remove_all(path);
        std::filesystem::create_directories(path);
    }
    ~TempDir() { std::filesystem::remove_all(path); }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    std::string operator/(const std::string& f) const { return (path / f).string(); }
};

/// A file's bytes.
inline std::string fileBytes(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
}

/// Where a serialised CObservation2DRangeScan (MRPT 2.5, version 7) keeps its beam count: the
/// uint32 before its `beams` ranges (float) and validity flags (char), which stdError (float),
/// timestamp (uint64), beamAperture (float) and the sensor label's length (uint32) follow;
/// `label_at` is where the label's text starts.
inline std::size_t scanBeamCountAt(std::size_t label_at, std::size_t beams) {
    return label_at - 4 - 4 - 8 - 4 - 5 * beams - 4;
}

/// `data` with the uint32 at byte `at` set to `value` (a corrupt length field).
inline std::string withU32(std::string data, std::size_t at, std::uint32_t value) {
    for (int i = 0; i < 4; ++i) data.at(at + i) = static_cast<char>(value >> (8 * i));
    return data;
}

}  // namespace test
}  // namespace kfd
