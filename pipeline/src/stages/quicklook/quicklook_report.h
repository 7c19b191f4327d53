#pragma once
// What the quick-look stage sends and stores: the JSON of its messages on the preview stream
// (docs/wire-protocol.md, "Quick-look messages"), their images, and the rows of /quicklook.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tomorig/core/frame_set.h"
#include "tomorig/processing/quicklook/drift_monitor.h"
#include "tomorig/processing/quicklook/dt_check.h"
#include "tomorig/processing/quicklook/preview_volume.h"
#include "tomorig/processing/quicklook/shadow_look.h"
#include "tomorig/processing/quicklook/statistics.h"
#include "tomorig/storage/quicklook_record.h"
#include "tomorig/stream/preview.h"

namespace tomorig::pipeline::quicklook_stage {

inline constexpr int kMessageVersion = 1;

// One camera's figures of one set.
struct CameraResult {
  std::string id;
  bool measured = false;     // both frames present and analysed
  std::string missing;       // why not, e.g. "frame B missing"
  quicklook::CameraQuickLook statistics;
  quicklook::DtCheckResult dt_check;
  // A shadowgraphy rig (the stage's shadow mode): the spray quick-look replaces the particle
  // statistics and the Δt check.
  bool shadow = false;
  quicklook::ShadowCameraLook shadow_look;
  quicklook::Flag flag() const;
};

// The newest preview volume and drift report, as the per-set messages repeat them.
struct PreviewSummary {
  bool available = false;
  std::uint64_t set = 0;
  quicklook::SheetProfile sheet;
  std::size_t active_voxels = 0;
  double seconds = 0;    // binning, reconstruction and profile
  double latency_s = 0;  // from the stage taking the set to the preview being done
};
struct DriftSummary {
  bool available = false;
  std::uint64_t set = 0;
  int sets = 0;  // pooled in the window
  quicklook::Flag flag = quicklook::Flag::amber;
  std::vector<double> largest_px;    // per camera
  std::vector<std::string> alarms;   // messages
};

struct Counts {
  std::uint64_t analysed = 0;          // sets this stage measured
  std::uint64_t skipped = 0;           // sets it never saw (gaps in the set index)
  std::uint64_t previews = 0;          // preview volumes made
  std::uint64_t previews_skipped = 0;  // sets the preview passed over to stay current
  std::uint64_t drift_alarm_sets = 0;
  std::uint64_t published = 0, dropped = 0;  // messages on the preview stream
  std::uint64_t stored = 0;                  // rows handed to the session file
};

nlohmann::json to_json(const PreviewSummary& p);
nlohmann::json to_json(const DriftSummary& d);
nlohmann::json to_json(const Counts& c);

// "tomorig.quicklook": one set's statistics and Δt checks, the newest preview and drift, with
// a thumbnail and a histogram picture per camera (frame A).
stream::PreviewMessage set_message(const FrameSet& set, const std::vector<CameraResult>& cameras,
                                   const PreviewSummary& preview, const DriftSummary& drift, const Counts& counts,
                                   int thumbnail_px);
// "tomorig.preview": one preview volume (profile included) and the drift report, with the three
// maximum-intensity projections.
stream::PreviewMessage preview_message(std::uint64_t set, const quicklook::PreviewResult& preview,
                                       const quicklook::DriftReport* drift, double latency_s, const Counts& counts);

// The /quicklook rows: one for a set's statistics, one for its preview volume and drift.
storage::QuickLookRecord statistics_record(std::uint64_t set, const std::vector<CameraResult>& cameras);
storage::QuickLookRecord preview_record(std::uint64_t set, std::size_t cameras, const quicklook::PreviewResult* preview,
                                        const quicklook::DriftReport* drift);

}  // namespace tomorig::pipeline::quicklook_stage
