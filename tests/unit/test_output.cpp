// Output writers: VTU frames read back by meshio, the .pvd series, CSV parsed back, and errors.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "motes/output.h"
#include "unit/test_support.h"

namespace fs = std::filesystem;

namespace {

using motes_test::TempDir;

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Particles with values that need all nine digits, signs, tiny and huge magnitudes.
motes::Snapshot sample_snapshot(std::uint64_t step, double time, float shift) {
  const std::vector<float> values = {0.1f, -1.0f / 3.0f, 1.0e-30f, -3.0e38f, 123456.789f,
                                     0.0f, 2.5f,         -0.75f,   1.0e-45f, 7.0f / 9.0f};
  motes::Snapshot s;
  s.step = step;
  s.time = time;
  for (std::size_t i = 0; i < 7; ++i) {
    auto v = [&](std::size_t k) { return values[(i * 3 + k) % values.size()] + shift; };
    s.particle_pos.emplace_back(v(0), v(1), v(2), 0.005f + 0.001f * static_cast<float>(i));
    s.particle_vel.emplace_back(v(3), -v(4), v(5), 1.0f);
    s.particle_body.push_back(static_cast<std::uint32_t>(i / 3 + (i == 6 ? 4000000000U : 0U)));
  }
  return s;
}

/// A Python interpreter that can import meshio, or "" if none.
std::string meshio_python() {
  for (const char* candidate : {"python3", "/usr/bin/python3"}) {
    const std::string cmd = std::string(candidate) + " -c 'import meshio' >/dev/null 2>&1";
    if (std::system(cmd.c_str()) == 0) return candidate;
  }
  return "";
}

/// Reads a .vtu with meshio; every array as JSON (Python floats print exactly).
nlohmann::json read_with_meshio(const std::string& python, const fs::path& vtu,
                                const fs::path& scratch) {
  const fs::path script = scratch / "read_vtu.py";
  const fs::path result = scratch / "vtu.json";
  std::ofstream(script) << R"(import json, sys, meshio
m = meshio.read(sys.argv[1])
print(json.dumps({
    "points": m.points.tolist(), "points_dtype": str(m.points.dtype),
    "cells": [[c.type, c.data.tolist()] for c in m.cells],
    "point_data": {k: v.tolist() for k, v in m.point_data.items()},
    "dtypes": {k: str(v.dtype) for k, v in m.point_data.items()},
    "field_data": {k: v.tolist() for k, v in m.field_data.items()},
}))
)";
  const std::string cmd =
      python + " '" + script.string() + "' '" + vtu.string() + "' > '" + result.string() + "'";
  if (std::system(cmd.c_str()) != 0) return nullptr;
  return nlohmann::json::parse(read_text(result));
}

void expect_vtu_matches(const nlohmann::json& m, const motes::Snapshot& s) {
  ASSERT_FALSE(m.is_null()) << "meshio could not read the file";
  const std::size_t n = s.particle_pos.size();
  EXPECT_EQ(m["points_dtype"], "float32");
  ASSERT_EQ(m["points"].size(), n);
  ASSERT_EQ(m["cells"].size(), 1u);
  EXPECT_EQ(m["cells"][0][0], "vertex");
  ASSERT_EQ(m["cells"][0][1].size(), n);
  EXPECT_EQ(m["dtypes"]["velocity"], "float32");
  EXPECT_EQ(m["dtypes"]["radius"], "float32");
  EXPECT_EQ(m["dtypes"]["body"], "uint32");
  EXPECT_EQ(m["dtypes"]["speed"], "float32");
  EXPECT_EQ(m["field_data"]["TimeValue"][0].get<double>(), s.time);
  const auto& pd = m["point_data"];
  for (std::size_t i = 0; i < n; ++i) {
    const auto& p = s.particle_pos[i];
    const auto& v = s.particle_vel[i];
    EXPECT_EQ(m["cells"][0][1][i][0].get<std::size_t>(), i);
    // float -> double is exact, so the doubles Python printed must equal the floats exactly.
    EXPECT_EQ(m["points"][i][0].get<double>(), double{p.x}) << "particle " << i;
    EXPECT_EQ(m["points"][i][1].get<double>(), double{p.y}) << "particle " << i;
    EXPECT_EQ(m["points"][i][2].get<double>(), double{p.z}) << "particle " << i;
    EXPECT_EQ(pd["velocity"][i][0].get<double>(), double{v.x}) << "particle " << i;
    EXPECT_EQ(pd["velocity"][i][1].get<double>(), double{v.y}) << "particle " << i;
    EXPECT_EQ(pd["velocity"][i][2].get<double>(), double{v.z}) << "particle " << i;
    EXPECT_EQ(pd["radius"][i].get<double>(), double{p.w}) << "particle " << i;
    EXPECT_EQ(pd["body"][i].get<std::uint32_t>(), s.particle_body[i]) << "particle " << i;
    const double vx = v.x, vy = v.y, vz = v.z;
    const auto speed = static_cast<float>(std::sqrt(vx * vx + vy * vy + vz * vz));
    EXPECT_EQ(pd["speed"][i].get<double>(), double{speed}) << "particle " << i;
  }
}

/// (file, timestep) of every DataSet in a .pvd.
std::vector<std::pair<std::string, double>> pvd_entries(const fs::path& pvd) {
  const std::string text = read_text(pvd);
  const std::regex entry(R"re(<DataSet timestep="([^"]*)"[^>]*file="([^"]*)"\s*/>)re");
  std::vector<std::pair<std::string, double>> out;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), entry);
       it != std::sregex_iterator(); ++it) {
    out.emplace_back((*it)[2].str(), std::strtod((*it)[1].str().c_str(), nullptr));
  }
  return out;
}

std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, sep)) out.push_back(field);
  return out;
}

float parse_float(const std::string& s) {
  char* end = nullptr;
  const float v = std::strtof(s.c_str(), &end);
  EXPECT_TRUE(end != s.c_str() && *end == '\0') << "not a float: '" << s << "'";
  return v;
}

TEST(OutputVtu, MeshioReadsEveryArrayExactly) {
  const std::string python = meshio_python();
  if (python.empty()) GTEST_SKIP() << "python3 with meshio not found (Debian: python3-meshio)";
  TempDir tmp;
  auto writer = motes::open_vtu_writer((tmp.path() / "run").string());
  ASSERT_TRUE(writer) << writer.message();
  const std::vector<motes::Snapshot> frames = {sample_snapshot(0, 0.0, 0.0f),
                                               sample_snapshot(10, 1.0 / 60.0, 0.5f),
                                               sample_snapshot(20, 2.0 / 60.0, -1.25f)};
  for (const auto& f : frames) ASSERT_TRUE(writer.value()->write_frame(f));
  ASSERT_TRUE(writer.value()->finish());
  EXPECT_EQ(writer.value()->frames(), 3u);
  EXPECT_EQ(writer.value()->main_path(), (tmp.path() / "run" / "particles.pvd").string());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    const fs::path vtu = tmp.path() / "run" / ("particles_00000" + std::to_string(i) + ".vtu");
    expect_vtu_matches(read_with_meshio(python, vtu, tmp.path()), frames[i]);
  }
}

TEST(OutputVtu, SeriesListsEveryFrameWithItsTimeAfterEachFrame) {
  TempDir tmp;
  const fs::path dir = tmp.path() / "a" / "b";  // created with its parents
  auto writer = motes::open_vtu_writer(dir.string());
  ASSERT_TRUE(writer) << writer.message();
  const fs::path pvd = dir / "particles.pvd";
  ASSERT_TRUE(fs::exists(pvd));
  EXPECT_TRUE(pvd_entries(pvd).empty());
  const double times[] = {0.0, 0.1, 1.0 / 3.0};
  for (std::size_t i = 0; i < 3; ++i) {
    ASSERT_TRUE(writer.value()->write_frame(sample_snapshot(i, times[i], 0.0f)));
    // The collection is complete after every frame, so an interrupted run still opens.
    const auto entries = pvd_entries(pvd);
    ASSERT_EQ(entries.size(), i + 1);
    for (std::size_t k = 0; k <= i; ++k) {
      // Appended: GCC 12 warns falsely (-Warray-bounds) on "..." + std::string temporaries.
      std::string name = "particles_00000";
      name += std::to_string(k);
      name += ".vtu";
      EXPECT_EQ(entries[k].first, name);
      EXPECT_EQ(entries[k].second, times[k]);
      EXPECT_TRUE(fs::exists(dir / entries[k].first));
    }
  }
  EXPECT_FALSE(fs::exists(dir / "particles.pvd.tmp"));
}

TEST(OutputCsv, HeaderAndRowsReadBackExactly) {
  TempDir tmp;
  auto writer = motes::open_csv_writer(tmp.path().string());
  ASSERT_TRUE(writer) << writer.message();
  const std::vector<motes::Snapshot> frames = {sample_snapshot(0, 0.0, 0.0f),
                                               sample_snapshot(5, 0.1, 2.0f)};
  for (const auto& f : frames) ASSERT_TRUE(writer.value()->write_frame(f));
  ASSERT_TRUE(writer.value()->finish());
  EXPECT_EQ(writer.value()->main_path(), (tmp.path() / "particles.csv").string());

  std::ifstream in(tmp.path() / "particles.csv");
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "frame,time,particle,body,x,y,z,vx,vy,vz");
  std::size_t rows = 0;
  while (std::getline(in, line)) {
    const auto f = split(line, ',');
    ASSERT_EQ(f.size(), 10u) << line;
    const std::size_t frame = std::stoul(f[0]);
    const std::size_t i = std::stoul(f[2]);
    ASSERT_LT(frame, frames.size());
    const motes::Snapshot& s = frames[frame];
    ASSERT_LT(i, s.particle_pos.size());
    EXPECT_EQ(rows, frame * s.particle_pos.size() + i) << "rows out of order";
    EXPECT_EQ(std::strtod(f[1].c_str(), nullptr), s.time);
    EXPECT_EQ(std::stoul(f[3]), s.particle_body[i]);
    EXPECT_EQ(parse_float(f[4]), s.particle_pos[i].x) << line;
    EXPECT_EQ(parse_float(f[5]), s.particle_pos[i].y) << line;
    EXPECT_EQ(parse_float(f[6]), s.particle_pos[i].z) << line;
    EXPECT_EQ(parse_float(f[7]), s.particle_vel[i].x) << line;
    EXPECT_EQ(parse_float(f[8]), s.particle_vel[i].y) << line;
    EXPECT_EQ(parse_float(f[9]), s.particle_vel[i].z) << line;
    ++rows;
  }
  EXPECT_EQ(rows, 14u);
}

TEST(OutputCsv, PointsFileAndParticleSetSnapshot) {
  TempDir tmp;
  const std::vector<Eigen::Vector3f> points = {{0.1f, -0.2f, 0.3f}, {1e-7f, 2.5f, -1.0f / 3.0f}};
  const fs::path csv = tmp.path() / "points.csv";
  ASSERT_TRUE(motes::write_points_csv(csv.string(), points));
  std::ifstream in(csv);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "x,y,z");
  for (const auto& p : points) {
    ASSERT_TRUE(std::getline(in, line));
    const auto f = split(line, ',');
    ASSERT_EQ(f.size(), 3u);
    EXPECT_EQ(parse_float(f[0]), p.x());
    EXPECT_EQ(parse_float(f[1]), p.y());
    EXPECT_EQ(parse_float(f[2]), p.z());
  }
  EXPECT_FALSE(std::getline(in, line));

  const motes::Snapshot s = motes::particle_set_snapshot(points, 0.02);
  ASSERT_EQ(s.particle_pos.size(), 2u);
  EXPECT_EQ(s.particle_pos[1].z, -1.0f / 3.0f);
  EXPECT_EQ(s.particle_pos[1].w, 0.01f);
  EXPECT_EQ(s.particle_vel[1].x, 0.0f);
  EXPECT_EQ(s.particle_body[1], 0u);
  const fs::path vtu = tmp.path() / "points.vtu";
  ASSERT_TRUE(motes::write_vtu_file(vtu.string(), s));
  const std::string python = meshio_python();
  if (!python.empty()) expect_vtu_matches(read_with_meshio(python, vtu, tmp.path()), s);
}

TEST(OutputErrors, DirectoryThatCannotBeCreatedNamesThePath) {
  TempDir tmp;
  // A regular file where a parent directory should be: fails even for root.
  const fs::path blocker = tmp.path() / "file";
  std::ofstream(blocker) << "x";
  const std::string dir = (blocker / "out").string();
  for (const auto format : {motes::OutputFormat::Vtu, motes::OutputFormat::Csv}) {
    auto writer = motes::open_frame_writer(format, dir);
    ASSERT_FALSE(writer);
    EXPECT_NE(writer.message().find(dir), std::string::npos) << writer.message();
  }
  const motes::Status s =
      motes::write_vtu_file((blocker / "x.vtu").string(), sample_snapshot(0, 0.0, 0.0f));
  ASSERT_FALSE(s);
  EXPECT_NE(s.message().find((blocker / "x.vtu").string()), std::string::npos) << s.message();
  EXPECT_FALSE(motes::write_points_csv((blocker / "x.csv").string(), {}));
  EXPECT_FALSE(motes::open_frame_writer(motes::OutputFormat::None, tmp.path().string()));
}

TEST(OutputErrors, FullDiskNamesTheFile) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full on this system";
  TempDir tmp;
  // /dev/full fails every write with ENOSPC, as a full disk does.
  fs::create_symlink("/dev/full", tmp.path() / "particles.csv");
  auto csv = motes::open_csv_writer(tmp.path().string());
  ASSERT_FALSE(csv);
  EXPECT_NE(csv.message().find("particles.csv"), std::string::npos) << csv.message();
  EXPECT_NE(csv.message().find("No space left"), std::string::npos) << csv.message();

  const fs::path vtu_dir = tmp.path() / "vtu";
  fs::create_directories(vtu_dir);
  fs::create_symlink("/dev/full", vtu_dir / "particles_000001.vtu");
  auto vtu = motes::open_vtu_writer(vtu_dir.string());
  ASSERT_TRUE(vtu) << vtu.message();
  EXPECT_TRUE(vtu.value()->write_frame(sample_snapshot(0, 0.0, 0.0f)));
  const motes::Status s = vtu.value()->write_frame(sample_snapshot(1, 0.5, 0.0f));
  ASSERT_FALSE(s);
  EXPECT_NE(s.message().find("particles_000001.vtu"), std::string::npos) << s.message();
  EXPECT_EQ(vtu.value()->frames(), 1u);
  EXPECT_EQ(pvd_entries(vtu_dir / "particles.pvd").size(), 1u);
}

TEST(OutputErrors, InconsistentSnapshotAndUnknownFormat) {
  TempDir tmp;
  motes::Snapshot s = sample_snapshot(3, 0.0, 0.0f);
  s.particle_body.pop_back();
  auto writer = motes::open_csv_writer(tmp.path().string());
  ASSERT_TRUE(writer);
  const motes::Status st = writer.value()->write_frame(s);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message().find("step 3"), std::string::npos) << st.message();
  EXPECT_FALSE(motes::write_vtu_file((tmp.path() / "x.vtu").string(), s));

  const auto bad = motes::parse_output_format("vtk");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.message().find("'vtk'"), std::string::npos) << bad.message();
  for (const auto f :
       {motes::OutputFormat::Vtu, motes::OutputFormat::Csv, motes::OutputFormat::None}) {
    EXPECT_EQ(motes::parse_output_format(motes::output_format_name(f)).value(), f);
  }
}

}  // namespace

namespace {

/// Three bodies with values that need all nine digits, added to a particle snapshot.
motes::Snapshot with_bodies(motes::Snapshot s, float shift) {
  for (int b = 0; b < 3; ++b) {
    const float f = static_cast<float>(b) + shift;
    s.body_pos.emplace_back(0.1f * f, -1.0f / 3.0f + f, 123456.789f - f, 0.5f);
    const float c = std::cos(0.3f * f);
    const float sn = std::sin(0.3f * f);
    s.body_quat.emplace_back(sn, 0.0f, 0.0f, c);
    s.body_vel.emplace_back(7.0f / 9.0f * f, -2.5f, 1.0e-30f, 0.0f);
    s.body_angvel.emplace_back(0.0f, 3.0e-7f * f, -11.0f, 0.0f);
    s.body_angmom.emplace_back(0.0f);
  }
  return s;
}

/// Splits one CSV line with RFC 4180 quoting ("a,b" and "" inside quotes).
std::vector<std::string> split_quoted(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
      out.back() += '"';
      ++i;
    } else if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

}  // namespace

TEST(OutputCsv, BodyTableReadsBackExactly) {
  TempDir tmp;
  const std::vector<std::string> names = {"plain", "with, comma", "say \"hi\""};
  auto writer = motes::open_csv_writer(tmp.path().string(), names);
  ASSERT_TRUE(writer) << writer.message();
  const std::vector<motes::Snapshot> frames = {with_bodies(sample_snapshot(0, 0.0, 0.0f), 0.0f),
                                               with_bodies(sample_snapshot(5, 0.1, 2.0f), 1.5f)};
  for (const auto& f : frames) ASSERT_TRUE(writer.value()->write_frame(f));
  ASSERT_TRUE(writer.value()->finish());

  std::ifstream in(tmp.path() / "bodies.csv");
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "frame,time,body,name,x,y,z,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz");
  std::size_t rows = 0;
  while (std::getline(in, line)) {
    const auto f = split_quoted(line);
    ASSERT_EQ(f.size(), 17u) << line;
    const std::size_t frame = std::stoul(f[0]);
    const std::size_t b = std::stoul(f[2]);
    ASSERT_LT(frame, frames.size());
    ASSERT_LT(b, names.size());
    EXPECT_EQ(rows, frame * names.size() + b) << "rows out of order";
    const motes::Snapshot& s = frames[frame];
    EXPECT_EQ(std::strtod(f[1].c_str(), nullptr), s.time);
    EXPECT_EQ(f[3], names[b]);
    const motes::shared::vec4 want[4] = {s.body_pos[b], s.body_quat[b], s.body_vel[b],
                                         s.body_angvel[b]};
    EXPECT_EQ(parse_float(f[4]), want[0].x) << line;
    EXPECT_EQ(parse_float(f[5]), want[0].y) << line;
    EXPECT_EQ(parse_float(f[6]), want[0].z) << line;
    EXPECT_EQ(parse_float(f[7]), want[1].x) << line;
    EXPECT_EQ(parse_float(f[8]), want[1].y) << line;
    EXPECT_EQ(parse_float(f[9]), want[1].z) << line;
    EXPECT_EQ(parse_float(f[10]), want[1].w) << line;
    EXPECT_EQ(parse_float(f[11]), want[2].x) << line;
    EXPECT_EQ(parse_float(f[12]), want[2].y) << line;
    EXPECT_EQ(parse_float(f[13]), want[2].z) << line;
    EXPECT_EQ(parse_float(f[14]), want[3].x) << line;
    EXPECT_EQ(parse_float(f[15]), want[3].y) << line;
    EXPECT_EQ(parse_float(f[16]), want[3].z) << line;
    ++rows;
  }
  EXPECT_EQ(rows, frames.size() * names.size());
}

TEST(OutputVtu, BodySeriesReadsBackExactly) {
  const std::string python = meshio_python();
  if (python.empty()) GTEST_SKIP() << "no Python with meshio (apt-get install python3-meshio)";
  TempDir tmp;
  const fs::path dir = tmp.path() / "run";
  auto writer = motes::open_vtu_writer(dir.string());
  ASSERT_TRUE(writer) << writer.message();
  const std::vector<motes::Snapshot> frames = {with_bodies(sample_snapshot(0, 0.0, 0.0f), 0.0f),
                                               with_bodies(sample_snapshot(5, 0.25, 2.0f), 1.5f)};
  for (const auto& f : frames) ASSERT_TRUE(writer.value()->write_frame(f));
  ASSERT_TRUE(writer.value()->finish());

  const auto entries = pvd_entries(dir / "bodies.pvd");
  ASSERT_EQ(entries.size(), frames.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    EXPECT_EQ(entries[k].first, fmt::format("bodies_{:06}.vtu", k));
    EXPECT_EQ(entries[k].second, frames[k].time);
    const motes::Snapshot& s = frames[k];
    const nlohmann::json m = read_with_meshio(python, dir / entries[k].first, tmp.path());
    ASSERT_FALSE(m.is_null()) << "meshio could not read " << entries[k].first;
    EXPECT_EQ(m["field_data"]["TimeValue"][0].get<double>(), s.time);
    ASSERT_EQ(m["points"].size(), s.body_pos.size());
    EXPECT_EQ(m["dtypes"]["orientation"], "float32");
    EXPECT_EQ(m["dtypes"]["angular_velocity"], "float32");
    EXPECT_EQ(m["dtypes"]["body"], "uint32");
    const auto& pd = m["point_data"];
    for (std::size_t b = 0; b < s.body_pos.size(); ++b) {
      EXPECT_EQ(m["points"][b][0].get<double>(), double{s.body_pos[b].x});
      EXPECT_EQ(m["points"][b][1].get<double>(), double{s.body_pos[b].y});
      EXPECT_EQ(m["points"][b][2].get<double>(), double{s.body_pos[b].z});
      EXPECT_EQ(pd["orientation"][b][0].get<double>(), double{s.body_quat[b].x});
      EXPECT_EQ(pd["orientation"][b][3].get<double>(), double{s.body_quat[b].w});
      EXPECT_EQ(pd["velocity"][b][0].get<double>(), double{s.body_vel[b].x});
      EXPECT_EQ(pd["angular_velocity"][b][1].get<double>(), double{s.body_angvel[b].y});
      EXPECT_EQ(pd["angular_velocity"][b][2].get<double>(), double{s.body_angvel[b].z});
      EXPECT_EQ(pd["body"][b].get<std::uint32_t>(), b);
    }
  }
}

TEST(OutputCsv, InconsistentBodyArraysAreRefused) {
  TempDir tmp;
  auto writer = motes::open_csv_writer(tmp.path().string());
  ASSERT_TRUE(writer) << writer.message();
  motes::Snapshot s = with_bodies(sample_snapshot(3, 0.0, 0.0f), 0.0f);
  s.body_angvel.pop_back();
  const motes::Status st = writer.value()->write_frame(s);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message().find("inconsistent snapshot at step 3"), std::string::npos)
      << st.message();
}

// A series continued by another writer (motes resume): the same files, byte for byte, as one
// writer that wrote every frame; rows and frames written after the recorded point are replaced.
TEST(OutputContinue, CsvAndVtuSeriesGoOnAsIfUninterrupted) {
  const std::vector<std::string> names = {"a", "b", "c"};
  std::vector<motes::Snapshot> frames;
  for (int k = 0; k < 5; ++k) {
    frames.push_back(with_bodies(
        sample_snapshot(static_cast<std::uint64_t>(k) * 10, 0.1 * k, static_cast<float>(k)),
        static_cast<float>(k)));
  }
  for (const motes::OutputFormat format : {motes::OutputFormat::Csv, motes::OutputFormat::Vtu}) {
    SCOPED_TRACE(motes::output_format_name(format));
    TempDir whole;
    TempDir parts;
    auto one = motes::open_frame_writer(format, whole.path().string(), names);
    ASSERT_TRUE(one) << one.message();
    for (const auto& f : frames) ASSERT_TRUE(one.value()->write_frame(f));
    ASSERT_TRUE(one.value()->finish());

    // Three frames, the state after them recorded, then a fourth written before the "crash".
    auto first = motes::open_frame_writer(format, parts.path().string(), names);
    ASSERT_TRUE(first) << first.message();
    motes::SeriesState state;
    for (int k = 0; k < 3; ++k) {
      ASSERT_TRUE(first.value()->write_frame(frames[static_cast<std::size_t>(k)]));
      state.frame_times.push_back(frames[static_cast<std::size_t>(k)].time);
    }
    if (format == motes::OutputFormat::Csv) {
      ASSERT_TRUE(motes::csv_series_sizes(parts.path().string(), state));
    }
    ASSERT_TRUE(first.value()->write_frame(with_bodies(sample_snapshot(99, 9.9, 9.0f), 9.0f)));
    first.value().reset();

    auto next = motes::continue_frame_writer(format, parts.path().string(), names, state);
    ASSERT_TRUE(next) << next.message();
    EXPECT_EQ(next.value()->frames(), 3u);
    for (std::size_t k = 3; k < frames.size(); ++k)
      ASSERT_TRUE(next.value()->write_frame(frames[k]));
    EXPECT_EQ(next.value()->frames(), 5u);
    ASSERT_TRUE(next.value()->finish());
    std::size_t files = 0;
    for (const auto& e : fs::directory_iterator(whole.path())) {
      ++files;
      EXPECT_EQ(read_text(e.path()), read_text(parts.path() / e.path().filename()))
          << e.path().filename();
    }
    EXPECT_EQ(files, format == motes::OutputFormat::Csv ? 2u : 12u);
  }
}

TEST(OutputContinue, MissingOrShortFilesAreRefusedAndNothingIsWritten) {
  TempDir tmp;
  const std::string dir = tmp.path().string();
  motes::SeriesState state;
  state.frame_times = {0.0, 0.1};
  // VTU: frame 1's files are missing.
  {
    auto w = motes::open_vtu_writer(dir);
    ASSERT_TRUE(w);
    ASSERT_TRUE(w.value()->write_frame(with_bodies(sample_snapshot(0, 0.0, 0.0f), 0.0f)));
  }
  const std::string pvd = read_text(tmp.path() / "particles.pvd");
  auto vtu = motes::continue_frame_writer(motes::OutputFormat::Vtu, dir, {}, state);
  ASSERT_FALSE(vtu);
  EXPECT_NE(vtu.message().find("particles_000001.vtu"), std::string::npos) << vtu.message();
  EXPECT_NE(vtu.message().find("missing"), std::string::npos) << vtu.message();
  EXPECT_EQ(read_text(tmp.path() / "particles.pvd"), pvd);
  // CSV: bodies.csv shorter than recorded; particles.csv is not cut either.
  {
    auto w = motes::open_csv_writer(dir);
    ASSERT_TRUE(w);
    ASSERT_TRUE(w.value()->write_frame(with_bodies(sample_snapshot(0, 0.0, 0.0f), 0.0f)));
  }
  ASSERT_TRUE(motes::csv_series_sizes(dir, state));
  const std::string particles = read_text(tmp.path() / "particles.csv");
  state.particles_csv_bytes -= 10;
  state.bodies_csv_bytes += 1;
  auto csv = motes::continue_frame_writer(motes::OutputFormat::Csv, dir, {}, state);
  ASSERT_FALSE(csv);
  EXPECT_NE(csv.message().find("bodies.csv"), std::string::npos) << csv.message();
  EXPECT_NE(csv.message().find("fewer than"), std::string::npos) << csv.message();
  EXPECT_EQ(read_text(tmp.path() / "particles.csv"), particles);
}
