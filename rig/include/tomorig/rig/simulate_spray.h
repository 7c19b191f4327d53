#pragma once
// `tomorig simulate --case spray-thesis`: the synthetic shadowgraphy case written as a session
// (docs/spray.md). Each set holds the 4 cameras' shadow images at pulses A and B. The truth:
// /truth/cameras the pinhole cameras; particles_a/b of set k the droplet centres; the truth's
// flow_name is the spray pattern and flow_parameters (JSON) holds the options, each camera's
// PSF chi(z), noise and threshold, the optics set-up as a TOML text for
// `tomorig optics visibility --setup`, and per set every droplet's diameter, per-camera
// minimum intensity and visibility.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "tomorig/config/rig_vocabulary.h"
#include "tomorig/simulators/spray.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::rig {

// The rig file's spray pattern ([simulation] spray, config's word) as the simulator's enum.
sim::SprayPattern sim_spray_pattern(config::SprayPattern pattern);
// A pattern named in config's words ("hollow-cone", "jet-in-crossflow"), e.g. `simulate
// --spray`; bad_input naming `option`, the word and the allowed words.
sim::SprayPattern parse_spray_pattern(const std::string& word, const std::string& option);

// The optics set-up of a case as the TOML `tomorig optics visibility --setup` reads.
std::string spray_optics_setup_toml(const sim::SprayCase& c);

// The rig config of the case as `tomorig run --config` reads it (the example rig's layout): the
// four simulated cameras, the 25 Hz trigger with the pulse separation, [simulation] with the
// seed, pattern, noise and pulse B's energy. Written into the sessions `write_spray_session` makes.
std::string spray_rig_config_toml(const sim::SprayCase& c, int sets);

// Renders `sets` sets and writes the session; returns a one-line summary. Throws bad_input if
// the file exists and `overwrite` is false, or for sets < 1.
std::string write_spray_session(const sim::SprayOptions& options, int sets, const std::filesystem::path& out,
                                storage::Compression compression, bool overwrite,
                                const std::function<void(int done, int total)>& progress = {});

// `--case spray-thesis --targets`: the knife-edge calibration series (Sect. 6.4). Set k holds
// each camera's image (exposure A; B missing) of the slanted bar photomask at depth k of the
// 13 PSF depths (-4.5 .. 4.5 mm, 0.75 mm apart). The truth: /truth/cameras; flow_name
// "traverse"; flow_parameters = {"planes": [{"set", "z_mm"}], "cameras": [{"id", "z_mm",
// "chi_um", ...}], "optics_setup_toml"} for `tomorig optics psf`.
std::string write_spray_target_session(const sim::SprayOptions& options, const std::filesystem::path& out,
                                       storage::Compression compression, bool overwrite);

}  // namespace tomorig::rig
