// The FAT volumes the sd_card part makes from a folder, checked by Debian's
// dosfstools (fsck.vfat) and mtools (mdir, mtype) - readers that are not
// ours - and images those tools make, read back by the part's reader (the
// file system the bench reads when a firmware prints from a card).
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "core/Errors.hpp"
#include "parts/FatVolume.hpp"
#include "support/RunCommand.hpp"

namespace avrbench {
namespace {

using test::quoted;
using test::run_command;
using test::scratch_dir;

// 5 000 bytes: two 2 KiB clusters and part of a third, so the chain matters.
std::string long_text() {
    std::string s;
    for (int i = 0; s.size() < 5000; ++i) s += "G1 X" + std::to_string(i % 100) + " Y" + std::to_string(i % 37) + "\n";
    return s.substr(0, 5000);
}

void write_file(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}
void write_file(const std::filesystem::path& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary);
    out << bytes;
}

TEST(FatVolume, AFolderCardIsAFat16VolumeFsckAndMtoolsRead) {
    const auto dir = scratch_dir("fat-made");
    const std::string job = long_text();
    const auto volume = make_fat16_volume({{"job.gco", job}, {"EMPTY.TXT", ""}, {"README", "hello\n"}}, "test");
    EXPECT_EQ(volume.size(), 32u << 20);
    write_file(dir / "card.img", volume);
    const std::string img = quoted((dir / "card.img").string());
    const auto fsck = run_command("fsck.vfat -n " + img, dir);
    EXPECT_EQ(fsck.exit_code, 0) << fsck.out << fsck.err;
    const auto minfo = run_command("minfo -i " + img + " ::", dir);
    EXPECT_NE(minfo.out.find("FAT16"), std::string::npos) << minfo.out << minfo.err;
    const auto mdir = run_command("mdir -b -i " + img + " ::", dir);
    EXPECT_EQ(mdir.out, "::/JOB.GCO\n::/EMPTY.TXT\n::/README\n") << mdir.err;
    const auto mtype = run_command("mtype -i " + img + " ::JOB.GCO", dir);
    EXPECT_EQ(mtype.out, job) << mtype.err;
}

TEST(FatVolume, NamesThatAreNot83AreRefusedWithTheName) {
    try {
        make_fat16_volume({{"job.gcode", "G1 X1\n"}}, "part 'sd': folder jobs");
        FAIL() << "no error";
    } catch (const BadInput& e) {
        EXPECT_EQ(std::string(e.what()).rfind("part 'sd': folder jobs: 'job.gcode' is not an 8.3 name", 0), 0u) << e.what();
    }
    EXPECT_THROW(make_fat16_volume({{"a.gco", ""}, {"A.GCO", ""}}, "x"), BadInput);
}

// mkfs.vfat picks FAT12 for 1 MiB, FAT16 for 32 MiB and, told to, FAT32 for 64 MiB.
struct MkfsCase {
    const char* options;  // mkfs.vfat's, before -C
    const char* kib;      // the image's size
    const char* label;
};
class FatImagesFromMkfs : public ::testing::TestWithParam<MkfsCase> {};

TEST_P(FatImagesFromMkfs, TheReaderListsAndReadsWhatMcopyPutThere) {
    const auto [options, kib, label] = GetParam();
    const auto dir = scratch_dir(std::string("fat-mkfs-") + label);
    const std::string job = long_text();
    write_file(dir / "part.gco", job);
    write_file(dir / "small.g", std::string("M105\n"));
    const std::string img = quoted((dir / "card.img").string());
    const auto mkfs = run_command(std::string("mkfs.vfat ") + options + " -C " + img + " " + kib, dir);
    ASSERT_EQ(mkfs.exit_code, 0) << mkfs.err;
    const auto mcopy = run_command("mcopy -i " + img + " " + quoted((dir / "part.gco").string()) + " " +
                                       quoted((dir / "small.g").string()) + " ::", dir);
    ASSERT_EQ(mcopy.exit_code, 0) << mcopy.err;
    const std::string bytes = test::slurp(dir / "card.img");
    const auto files = read_fat_root_files(std::vector<std::uint8_t>(bytes.begin(), bytes.end()));
    ASSERT_TRUE(files.has_value());
    ASSERT_EQ(files->size(), 2u);
    EXPECT_EQ((*files)[0].name, "PART.GCO");
    EXPECT_EQ((*files)[0].bytes, job);
    EXPECT_EQ((*files)[1].name, "SMALL.G");
    EXPECT_EQ((*files)[1].bytes, "M105\n");
}

INSTANTIATE_TEST_SUITE_P(Types, FatImagesFromMkfs,
                         ::testing::Values(MkfsCase{"", "1024", "fat12"}, MkfsCase{"", "32768", "fat16"},
                                           MkfsCase{"-F 32", "65536", "fat32"}),
                         [](const auto& test_case) { return std::string(test_case.param.label); });

TEST(FatVolume, AnImageWithoutAFileSystemHasNoFiles) {
    EXPECT_FALSE(read_fat_root_files(std::vector<std::uint8_t>(1 << 20, 0)).has_value());
}

}  // namespace
}  // namespace avrbench
