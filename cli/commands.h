// The subcommands of `motes`: each lives in its own cmd_*.cpp and registers itself on the app.
#pragma once

#include <CLI/CLI.hpp>

namespace motes::cli {

/// `motes run [SCENE]`: runs a scene and writes frames (cmd_run.cpp).
void add_run_command(CLI::App& app);
/// `motes resume CHECKPOINT`: goes on with a run from a checkpoint (cmd_resume.cpp).
void add_resume_command(CLI::App& app);
/// `motes devices`: every backend, its devices or why it has none (cmd_devices.cpp).
void add_devices_command(CLI::App& app);
/// `motes voxelize MESH`: fills a mesh with particles (cmd_voxelize.cpp).
void add_voxelize_command(CLI::App& app);
/// `motes bench`: the fixed benchmark workloads (cmd_bench.cpp).
void add_bench_command(CLI::App& app);
/// `motes render RESULTS`: pictures and video of frames written by motes run (cmd_render.cpp).
void add_render_command(CLI::App& app);
/// `motes view SCENE`: the scene in a window, stepped in real time (cmd_view.cpp).
void add_view_command(CLI::App& app);
/// `motes render-bench`: times the renderer on a block of particles (cmd_render_bench.cpp).
void add_render_bench_command(CLI::App& app);

}  // namespace motes::cli
