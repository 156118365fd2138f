// kfd's checked gzip and PNG writers (kfd/io/gz_output.h, kfd/io/png_output.h): the same
// bytes as MRPT's writers, and a failed write is a WriteError that names the file and the reason.
#include "kfd/io/gz_output.h"

#include <gtest/gtest.h>
#include <mrpt/img/CImage.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/serialization/CArchive.h>

#include <filesystem>
#include <string>

#include "kfd/io/png_output.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using kfd::test::fileBytes;

struct Dir : kfd::test::TempDir {
    Dir() : TempDir("kfd_gz_output_") {}
};

// A few hundred scans of varied ranges (compressible, several deflate blocks).
std::vector<mrpt::obs::CObservation2DRangeScan> someScans() {
    std::vector<mrpt::obs::CObservation2DRangeScan> scans(300);
    for (std::size_t k = 0; k < scans.size(); ++k) {
        auto& s = scans[k];
        s.sensorLabel = "LASER";
        s.aperture = 3.14f;
        s.resizeScan(361);
        for (std::size_t i = 0; i < 361; ++i) {
            s.setScanRange(i, 1.0f + 0.01f * static_cast<float>((i * 7 + k * 13) % 97));
            s.setScanRangeValidity(i, i % 11 != 0);
        }
    }
    return scans;
}

TEST(GzOutput, SameBytesAsMrptsGzipStreamAtEveryLevel) {
    Dir d;
    const auto scans = someScans();
    for (const int level : {0, 1, 6, 9}) {
        const std::string ours = d / "ours.gz", theirs = d / "theirs.gz";
        {
            kfd::GzOutputStream out(ours, "ours.gz", level);
            for (const auto& s : scans) out.write(s);
            out.close();
            EXPECT_GT(out.getTotalBytesCount(), 300u * 361u);
        }
        {
            mrpt::io::CFileGZOutputStream out(theirs, mrpt::io::OpenMode::TRUNCATE, level);
            auto arch = mrpt::serialization::archiveFrom(out);
            for (const auto& s : scans) arch << s;
        }
        EXPECT_TRUE(fileBytes(ours) == fileBytes(theirs)) << "level " << level;
        // And MRPT reads it back.
        mrpt::io::CFileGZInputStream in(ours);
        auto arch = mrpt::serialization::archiveFrom(in);
        mrpt::obs::CObservation2DRangeScan back;
        arch >> back;
        EXPECT_EQ(back.getScanSize(), 361u);
        EXPECT_EQ(back.getScanRange(5), scans[0].getScanRange(5));
    }
}

TEST(GzOutput, AFullDeviceIsAWriteErrorNamingTheFileNotAnMrptTrace) {
    if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
    const auto scans = someScans();
    try {
        kfd::GzOutputStream out("/dev/full", "/data/out.rawlog", 0);
        for (const auto& s : scans) out.write(s);  // fails at the first full buffer
        out.close();
        ADD_FAILURE() << "no error";
    } catch (const kfd::WriteError& e) {
        EXPECT_EQ(std::string(e.what()), "cannot write /data/out.rawlog: No space left on device");
        EXPECT_EQ(e.field(), "/data/out.rawlog");
    }
    try {  // a small stream fails at close (the end of the stream)
        kfd::GzOutputStream out("/dev/full", "/data/small.rawlog", 1);
        out.write(scans[0]);
        out.close();
        ADD_FAILURE() << "no error";
    } catch (const kfd::WriteError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "cannot write /data/small.rawlog: No space left on device");
    }
}

mrpt::img::CImage testImage(mrpt::img::TImageChannels channels) {
    mrpt::img::CImage img(320, 200, channels);
    for (unsigned y = 0; y < 200; ++y)
        for (unsigned x = 0; x < 320; ++x)
            img.setPixel(static_cast<int>(x), static_cast<int>(y),
                         mrpt::img::TColor(static_cast<uint8_t>(x), static_cast<uint8_t>(y),
                                           static_cast<uint8_t>((x * y) % 251)));
    return img;
}

TEST(PngOutput, SameBytesAsCImageSaveToFile) {
    Dir d;
    for (const auto channels : {mrpt::img::CH_GRAY, mrpt::img::CH_RGB}) {
        const auto img = testImage(channels);
        kfd::writePng(img, d / "ours.png", "ours.png");
        ASSERT_TRUE(img.saveToFile(d / "theirs.png"));
        EXPECT_TRUE(fileBytes(d / "ours.png") == fileBytes(d / "theirs.png"))
            << static_cast<int>(channels) << " channel(s)";
        mrpt::img::CImage back;
        ASSERT_TRUE(back.loadFromFile(d / "ours.png"));
        EXPECT_EQ(back.getWidth(), 320u);
    }
}

TEST(PngOutput, AFullDeviceIsAWriteErrorAndLibpngSaysNothing) {
    if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
    testing::internal::CaptureStderr();
    try {
        kfd::writePng(testImage(mrpt::img::CH_RGB), "/dev/full", "/data/map.png");
        ADD_FAILURE() << "no error";
    } catch (const kfd::WriteError& e) {
        EXPECT_EQ(std::string(e.what()), "cannot write /data/map.png: No space left on device");
    }
    EXPECT_EQ(testing::internal::GetCapturedStderr(), "");  // no "libpng error: Write Error"
}

}  // namespace
