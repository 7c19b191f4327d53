// The PSF file of `tomorig optics psf --psf-out`: what it writes reads back, and `--psf` tells it
// from an optics set-up file by its structure, not by a word somewhere in the text (a set-up
// file whose comment mentioned sigma_px was taken for a PSF file before `kind` existed).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tomorig/core/error.h"
#include "tomorig/processing/optics/psf_table.h"

namespace tomorig::optics {
namespace {

PsfTable two_depth_table() {
  PsfTable t;
  t.voxel_mm = 0.03;
  t.cameras.push_back({"cam1", {-4.5, 4.5}, {60.0, 57.0}, {64.0, 61.0}, {1.02, 0.95}});
  return t;
}

std::filesystem::path write_file(const std::string& name, const std::string& text) {
  const std::filesystem::path p = std::filesystem::temp_directory_path() / name;
  std::ofstream(p) << text;
  return p;
}

TEST(PsfTable, WhatIsWrittenReadsBackAndIsRecognisedAsAPsfFile) {
  const PsfTable t = two_depth_table();
  const std::filesystem::path p = write_file("tomorig-psf-table-roundtrip.toml", psf_table_toml(t, "measured"));
  const PsfTable back = read_psf_table(p);
  ASSERT_EQ(back.cameras.size(), 1u);
  EXPECT_EQ(back.cameras[0].id, "cam1");
  EXPECT_DOUBLE_EQ(back.cameras[0].sigma_px[1], 0.95);
  EXPECT_TRUE(is_psf_table_file(p));
  std::filesystem::remove(p);
}

TEST(PsfTable, AFileWithoutKindIsAPsfFileWhenItsCamerasHoldSigma) {
  const std::filesystem::path p = write_file("tomorig-psf-table-old.toml",
                                             "voxel_mm = 0.03\n[[cameras]]\nid = \"cam1\"\nz_mm = [0.0]\n"
                                             "chi_um = [40.0]\nchi_voxel_um = [44.0]\nsigma_px = [0.7]\n");
  EXPECT_TRUE(is_psf_table_file(p));
  EXPECT_NO_THROW(read_psf_table(p));
  std::filesystem::remove(p);
}

TEST(PsfTable, ASetUpFileMentioningSigmaInACommentIsNotAPsfFile) {
  const std::filesystem::path p = write_file("tomorig-optics-setup.toml",
                                             "# chi(z) per camera; the reconstruction derives sigma_px from it\n"
                                             "[[cameras]]\nid = \"cam1\"\nf_number = 22.0\nmagnification = 0.9\n"
                                             "z_mm = [0.0]\nchi_um = [40.0]\n");
  EXPECT_FALSE(is_psf_table_file(p));
  EXPECT_FALSE(is_psf_table_file(std::filesystem::temp_directory_path() / "tomorig-no-such-psf.toml"));
  std::filesystem::remove(p);
}

TEST(PsfTable, AnotherKindIsRefusedNamingTheKey) {
  const std::filesystem::path p = write_file("tomorig-psf-table-kind.toml",
                                             "kind = \"optics-setup\"\nvoxel_mm = 0.03\n[[cameras]]\nid = \"cam1\"\n"
                                             "z_mm = [0.0]\nchi_um = [40.0]\nchi_voxel_um = [44.0]\nsigma_px = [0.7]\n");
  EXPECT_FALSE(is_psf_table_file(p));
  try {
    read_psf_table(p);
    FAIL() << "a PSF file of another kind was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("kind"), std::string::npos) << e.what();
  }
  std::filesystem::remove(p);
}

}  // namespace
}  // namespace tomorig::optics
