// The motes command: `motes run`, `motes resume`, `motes devices`, `motes voxelize`, `motes bench`,
// `motes render`.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <new>

#include "cli_util.h"
#include "commands.h"
#include "run_mpi.h"

int main(int argc, char** argv) {
  // Under mpirun: MPI from here to the end of main (docs/scale-out.md).
  motes::cli::MpiSession mpi(argc, argv);
  CLI::App app("motes: rigid bodies made of particles, on OpenMP, CUDA and Vulkan", "motes");
  app.set_version_flag("--version", std::string("motes ") + MOTES_VERSION);
  app.require_subcommand(1);
  motes::cli::add_run_command(app);
  motes::cli::add_resume_command(app);
  motes::cli::add_devices_command(app);
  motes::cli::add_voxelize_command(app);
  motes::cli::add_bench_command(app);
  motes::cli::add_render_command(app);
  motes::cli::add_render_bench_command(app);
  motes::cli::add_view_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    std::fflush(stdout);
    return app.exit(e);
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "motes: error: out of memory\n");
    return motes::cli::kErrorExit;
  } catch (const std::exception& e) {
    fmt::print(stderr, "motes: error: {}\n", e.what());
    return motes::cli::kErrorExit;
  }
  return 0;
}
