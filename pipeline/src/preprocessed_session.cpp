#include "tomorig/pipeline/preprocessed_session.h"

#include "tomorig/core/set_selection.h"
#include "tomorig/pipeline/session_preprocessor.h"
#include "tomorig/storage/output_path.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::pipeline {

PreprocessedSessionReport write_preprocessed_session(const PreprocessedSessionOptions& options,
                                                     const PreprocessProgress& progress) {
  storage::check_output_path(options.out, options.overwrite, "session");
  const storage::SessionReader session(options.session);
  const SetSelection selection = options.sets.empty() ? SetSelection() : SetSelection::parse(options.sets);
  const auto [first, end] = selection.range(session.set_count());
  PreprocessedSessionReport report;
  report.first_set = first;
  report.sets = end - first;
  report.cameras = session.info().cameras.size();
  // The sequence passes, then the one that writes.
  const auto tell = [&](std::size_t pass, std::size_t sequence_passes, std::uint64_t done) {
    if (progress) progress(pass, sequence_passes + 1, done, report.sets);
  };
  SessionPreprocessor chains(session, options.chain, selection, tell);
  report.steps = chains.steps();
  report.passes = chains.sequence_passes() + 1;

  storage::SessionInfo info = session.info();
  info.software_version.clear();
  info.created_utc.clear();
  for (auto& camera : info.cameras) camera.pixel_format = PixelFormat::Mono16;
  storage::SessionWriterOptions writer_options;
  writer_options.compression = session.info().compression;
  writer_options.overwrite = options.overwrite;
  storage::SessionWriter writer(options.out, info, writer_options);
  if (session.has_truth()) writer.write_truth(session.truth());
  for (std::uint64_t s = first; s < end; ++s) {
    FrameSet set = session.read_set(s);
    chains.apply_as_uint16(set);
    writer.append(set);
    if (session.has_truth_set(s)) writer.write_truth_set(s - first, session.truth_set(s));
    if (progress) progress(report.passes - 1, report.passes, s - first + 1, report.sets);
  }
  writer.finish();
  return report;
}

}  // namespace tomorig::pipeline
