#pragma once
// The real data the real-data tests read (../shared/data: the fluidimage TomoPIV sample). Where
// that folder exists (CI, the main checkout) the build sets TOMORIG_REAL_DATA_REQUIRED=1 and a
// missing sample fails the test; elsewhere (a fresh clone, a worktree) the test is skipped. The
// tests carry the ctest label `real_data` (cmake/TomorigModule.cmake).
#include <filesystem>

#include <gtest/gtest.h>

#ifndef TOMORIG_REAL_DATA_REQUIRED
#define TOMORIG_REAL_DATA_REQUIRED 0
#endif

// In a TEST body: skip, or fail where the data is required, unless `sample` exists.
#define TOMORIG_NEED_REAL_DATA(sample)                                                                    \
  do {                                                                                                    \
    if (!std::filesystem::exists(sample)) {                                                               \
      if (TOMORIG_REAL_DATA_REQUIRED) FAIL() << "real-data sample missing: " << (sample).string();        \
      GTEST_SKIP() << "real-data sample not found (not required here): " << (sample).string();            \
    }                                                                                                     \
  } while (false)
