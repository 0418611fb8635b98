// motes::DistributedSimulation (motes/distributed.h, docs/scale-out.md): ownership by brick,
// whole-body records sent to new owners at each partition, halo copies refreshed after every step.
#include "motes/distributed.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "distributed_internal.h"
#include "shared/halo.h"

namespace motes {

using shared::vec4;

namespace {

using Clock = std::chrono::steady_clock;

/// One vec4 on the wire.
MPI_Datatype vec4_type() {
  static MPI_Datatype type = [] {
    MPI_Datatype t;
    MPI_Type_contiguous(4, MPI_FLOAT, &t);
    MPI_Type_commit(&t);
    return t;
  }();
  return type;
}

/// Sends out[r] to rank r and returns what every rank sent here, in rank order, with the
/// counts per source rank (collective).
Result<std::vector<vec4>> all_to_all(MPI_Comm comm, const std::vector<std::vector<vec4>>& out,
                                     std::vector<int>& received) {
  const int size = static_cast<int>(out.size());
  std::vector<int> sent(out.size()), sent_at(out.size()), received_at(out.size());
  received.assign(out.size(), 0);
  bool too_big = false;
  std::size_t total = 0;
  for (std::size_t r = 0; r < out.size(); ++r) {
    too_big = too_big || out[r].size() > static_cast<std::size_t>(std::numeric_limits<int>::max());
    sent[r] = static_cast<int>(out[r].size());
    total += out[r].size();
  }
  too_big = too_big || total > static_cast<std::size_t>(std::numeric_limits<int>::max());
  if (too_big) {
    // Nothing is sent; the caller's agree() reports it on every rank.
    for (int& c : sent) c = 0;
  }
  std::vector<vec4> packed;
  packed.reserve(total);
  for (std::size_t r = 0; r < out.size(); ++r) {
    sent_at[r] = static_cast<int>(packed.size());
    packed.insert(packed.end(), out[r].begin(), out[r].end());
  }
  MPI_Alltoall(sent.data(), 1, MPI_INT, received.data(), 1, MPI_INT, comm);
  std::size_t incoming = 0;
  for (int r = 0; r < size; ++r) {
    received_at[static_cast<std::size_t>(r)] = static_cast<int>(incoming);
    incoming += static_cast<std::size_t>(received[static_cast<std::size_t>(r)]);
  }
  std::vector<vec4> in(incoming);
  MPI_Alltoallv(packed.data(), sent.data(), sent_at.data(), vec4_type(), in.data(), received.data(),
                received_at.data(), vec4_type(), comm);
  if (too_big) return Status::error("more than 2^31 vec4s to send in one exchange");
  return in;
}

using Record = DistributedSimulation::Record;

template <typename T>
Status status_of(const Result<T>& r) {
  return r ? Status::ok() : r.status();
}

/// A record on the wire: (body, particles, cluster rotations, plane impulses) as bits, the six
/// body vectors, the positions, the velocities, the rotations, the plane impulses.
void append(std::vector<vec4>& out, const Record& r) {
  const auto bits = [](std::size_t n) {
    return std::bit_cast<float>(static_cast<std::uint32_t>(n));
  };
  out.push_back(vec4(std::bit_cast<float>(r.body), bits(r.pos.size()), bits(r.rotations.size()),
                     bits(r.planes.size())));
  out.insert(out.end(), r.state.begin(), r.state.end());
  out.insert(out.end(), r.pos.begin(), r.pos.end());
  out.insert(out.end(), r.vel.begin(), r.vel.end());
  out.insert(out.end(), r.rotations.begin(), r.rotations.end());
  out.insert(out.end(), r.planes.begin(), r.planes.end());
}

/// The records in `in`, as append wrote them; with `counts` (vec4s from each rank, in rank
/// order), `source` gets each record's rank.
std::vector<Record> parse(const std::vector<vec4>& in, const std::vector<int>* counts = nullptr,
                          std::vector<int>* source = nullptr) {
  std::vector<Record> records;
  std::size_t rank = 0;
  std::size_t rank_end = counts != nullptr && !counts->empty() ? (*counts)[0] : in.size();
  for (std::size_t at = 0; at < in.size();) {
    while (counts != nullptr && at >= rank_end && rank + 1 < counts->size()) {
      rank_end += static_cast<std::size_t>((*counts)[++rank]);
    }
    Record r;
    r.body = std::bit_cast<std::uint32_t>(in[at].x);
    const std::size_t n = std::bit_cast<std::uint32_t>(in[at].y);
    const std::size_t c = std::bit_cast<std::uint32_t>(in[at].z);
    const std::size_t q = std::bit_cast<std::uint32_t>(in[at].w);
    std::copy_n(in.begin() + static_cast<std::ptrdiff_t>(at + 1), r.state.size(), r.state.begin());
    auto next = in.begin() + static_cast<std::ptrdiff_t>(at + 1 + r.state.size());
    const auto take = [&next](std::vector<vec4>& v, std::size_t count) {
      v.assign(next, next + static_cast<std::ptrdiff_t>(count));
      next += static_cast<std::ptrdiff_t>(count);
    };
    take(r.pos, n);
    take(r.vel, n);
    take(r.rotations, c);
    take(r.planes, q);
    at += 1 + r.state.size() + 2 * n + c + q;
    records.push_back(std::move(r));
    if (source != nullptr) source->push_back(static_cast<int>(rank));
  }
  return records;
}

Eigen::Vector3d centre_of(const vec4& v) {
  return {static_cast<double>(v.x), static_cast<double>(v.y), static_cast<double>(v.z)};
}

/// Lower and upper corners of a record's particles, each grown by its radius.
std::array<double, 6> record_box(const Record& r) {
  std::array<double, 6> box{};
  for (int a = 0; a < 3; ++a) {
    box[static_cast<std::size_t>(a)] = std::numeric_limits<double>::infinity();
    box[static_cast<std::size_t>(a + 3)] = -std::numeric_limits<double>::infinity();
  }
  for (const vec4& p : r.pos) {
    const Eigen::Vector3d c = centre_of(p);
    const double radius = static_cast<double>(p.w);
    for (int a = 0; a < 3; ++a) {
      box[static_cast<std::size_t>(a)] = std::min(box[static_cast<std::size_t>(a)], c[a] - radius);
      box[static_cast<std::size_t>(a + 3)] =
          std::max(box[static_cast<std::size_t>(a + 3)], c[a] + radius);
    }
  }
  return box;
}

bool overlap(const std::array<double, 6>& a, const double* b) {
  for (int k = 0; k < 3; ++k) {
    if (a[static_cast<std::size_t>(k)] > b[k + 3] || b[k] > a[static_cast<std::size_t>(k + 3)]) {
      return false;
    }
  }
  return true;
}

/// Lower and upper corners that hold a body's particles wherever the scene turns it: its centre
/// of mass (BodySpec::position) plus or minus the largest distance of a particle from the
/// shape's centre of mass (the mean of its points) and its radius; `reach` caches that per
/// shape.
std::array<double, 6> spec_box(const BodySpec& b,
                               std::unordered_map<const ParticleSet*, double>& reach) {
  auto [it, fresh] = reach.try_emplace(b.shape.get(), 0.0);
  if (fresh && b.shape && !b.shape->points.empty()) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3f& p : b.shape->points) mean += p.cast<double>();
    mean /= static_cast<double>(b.shape->points.size());
    double far = 0.0;
    for (const Eigen::Vector3f& p : b.shape->points) {
      far = std::max(far, (p.cast<double>() - mean).norm());
    }
    // A little more than the float particles' rounding can add.
    it->second = far * (1.0 + 1e-6) + 0.5 * b.shape->diameter;
  }
  return {b.position.x() - it->second, b.position.y() - it->second, b.position.z() - it->second,
          b.position.x() + it->second, b.position.y() + it->second, b.position.z() + it->second};
}

/// The same for a cloth or rope: its points' bounds grown by their radius.
std::array<double, 6> spec_box(const LinkedSpec& l) {
  std::array<double, 6> box{};
  for (int a = 0; a < 3; ++a) {
    box[static_cast<std::size_t>(a)] = std::numeric_limits<double>::infinity();
    box[static_cast<std::size_t>(a + 3)] = -std::numeric_limits<double>::infinity();
  }
  for (const Eigen::Vector3d& p : l.points) {
    for (int a = 0; a < 3; ++a) {
      box[static_cast<std::size_t>(a)] =
          std::min(box[static_cast<std::size_t>(a)], p[a] - 0.5 * l.diameter);
      box[static_cast<std::size_t>(a + 3)] =
          std::max(box[static_cast<std::size_t>(a + 3)], p[a] + 0.5 * l.diameter);
    }
  }
  return box;
}

using detail::sub_scene;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

Status agree(MPI_Comm comm, const Status& mine, double* largest) {
  int rank = 0;
  int size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  // One reduction: the largest of `largest`, and size - (lowest failing rank) (0: none failed).
  double in[2] = {largest != nullptr ? *largest : 0.0,
                  mine ? 0.0 : static_cast<double>(size - rank)};
  double out[2] = {0.0, 0.0};
  MPI_Allreduce(in, out, 2, MPI_DOUBLE, MPI_MAX, comm);
  if (largest != nullptr) *largest = out[0];
  if (out[1] == 0.0) return Status::ok();
  const int first = size - static_cast<int>(out[1]);
  // A failure every rank shares (a scene it cannot split, a wrong decomposition) needs no rank.
  int failures = mine ? 0 : 1;
  int total = 0;
  MPI_Allreduce(&failures, &total, 1, MPI_INT, MPI_SUM, comm);
  std::string text = rank == first ? mine.message() : std::string();
  int length = static_cast<int>(text.size());
  MPI_Bcast(&length, 1, MPI_INT, first, comm);
  text.resize(static_cast<std::size_t>(length));
  MPI_Bcast(text.data(), length, MPI_CHAR, first, comm);
  return Status::error(total < size ? fmt::format("rank {}: {}", first, text) : text);
}

Result<std::unique_ptr<DistributedSimulation>> DistributedSimulation::create(
    Scene whole, MPI_Comm comm, DeviceOpener open_device, const DistributedOptions& options) {
  std::unique_ptr<DistributedSimulation> d(new DistributedSimulation());
  d->comm_ = comm;
  MPI_Comm_rank(comm, &d->rank_);
  MPI_Comm_size(comm, &d->size_);
  d->open_device_ = std::move(open_device);
  d->scene_ = std::move(whole);
  // Every rank refuses a scene with fluids: the partition and the halo carry bodies, and a rank's
  // own scene would leave the liquid out (fluids run in one process: docs/fluids.md).
  if (!d->scene_.fluids.empty()) {
    return Status::error(
        fmt::format("{}: fluid \"{}\": fluids do not run over MPI ranks yet (one process runs "
                    "them: docs/fluids.md)",
                    d->scene_.source, d->scene_.fluids.front().name));
  }
  // The impulse contacts' memory is each rank's own and does not travel with a partition (which
  // makes the ranks' simulations anew): it is dropped at every list build, on every rank count.
  d->scene_.settings.impulse_memory_across_builds = false;
  d->group_bodies();
  const Scene& scene = d->scene_;
  const std::vector<Eigen::Vector3d> centres = body_centres(scene);
  Result<Decomposition> decomposition =
      choose_decomposition(centres, d->size_, options.decomposition);
  if (Status s = agree(comm, status_of(decomposition)); !s) return s;
  d->decomposition_ = decomposition.value();

  // The scene's bodies as a gathered Snapshot lays them out, as Simulation::create starts its
  // layout (a soft body's energy is its particles', motes/energy.h).
  SceneBodies all = scene_bodies(scene);
  d->bodies_ = std::move(all.bodies);
  d->particles_ = all.particles;
  d->scene_diameter_ = all.largest_diameter;
  const double diameter = d->scene_diameter_;
  // Every rank's lists have the skin of one process's (Simulation: the scene's largest diameter).
  d->skin_ = Simulation::neighbour_skin(scene.settings, diameter);
  // Between two list builds a particle moves up to 0.45 skin (a rebuild is due then), also right
  // after a partition: the halo's two margins must hold that much movement of both particles of a
  // pair, or a rank could miss a contact across its border.
  if (std::isnan(options.margin) || std::isinf(options.margin) ||
      (options.margin >= 0.0 && options.margin < 0.5 * d->skin_)) {
    return Status::error(fmt::format(
        "{}: a partition margin of {} m: it must be finite and at least half the neighbour skin "
        "({} m; a particle moves up to 0.45 skin between list builds, and a smaller margin would "
        "let ranks miss contacts across their borders), or < 0 for half the largest particle "
        "diameter ({} m)",
        scene.source, options.margin, 0.5 * d->skin_, 0.5 * diameter));
  }
  d->margin_ = options.margin >= 0.0 ? options.margin : 0.5 * diameter;
  d->halo_mode_ = options.halo;
  MPI_Comm host = MPI_COMM_NULL;
  MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &host);
  int on_host = 0;
  MPI_Comm_size(host, &on_host);
  MPI_Comm_free(&host);
  d->one_host_ = on_host == d->size_;
  d->halo_width_ = 2.0 * d->margin_;

  if (Status s = d->first_partition(centres); !s) return s;
  return d;
}

Status DistributedSimulation::first_partition(const std::vector<Eigen::Vector3d>& centres) {
  // The first partition from the scene alone, the same on every rank: each group belongs to the
  // rank whose brick holds its centre, and its copies go where its particles, as the scene places
  // them (within a sphere about each body's centre that holds its shape in any orientation), come
  // within two margins of another rank's. No state travels: each rank builds its bodies and
  // copies from the scene.
  const auto ranks = static_cast<std::size_t>(size_);
  const std::size_t count = centres.size();
  std::vector<int> group_owner(groups_.size());
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const std::uint32_t b : groups_[g]) centre += centres[b];
    group_owner[g] = decomposition_.owner(centre / static_cast<double>(groups_[g].size()));
  }
  std::vector<int> owner(count);
  std::vector<std::array<double, 6>> boxes(count);
  std::unordered_map<const ParticleSet*, double> reach;  // per shape
  const std::size_t rigid = scene_.bodies.size();
  std::vector<double> regions(6 * ranks);
  for (std::size_t r = 0; r < ranks; ++r) {
    for (int a = 0; a < 3; ++a) {
      regions[6 * r + a] = std::numeric_limits<double>::infinity();
      regions[6 * r + a + 3] = -std::numeric_limits<double>::infinity();
    }
  }
  for (std::uint32_t b = 0; b < count; ++b) {
    const std::uint32_t g = group_of_[b];
    owner[b] = g == kAlone ? decomposition_.owner(centres[b]) : group_owner[g];
    boxes[b] = b < rigid ? spec_box(scene_.bodies[b], reach) : spec_box(scene_.linked[b - rigid]);
    double* region = &regions[6 * static_cast<std::size_t>(owner[b])];
    for (std::size_t a = 0; a < 3; ++a) {
      region[a] = std::min(region[a], boxes[b][a] - halo_width_);
      region[a + 3] = std::max(region[a + 3], boxes[b][a + 3] + halo_width_);
    }
  }
  for (const std::vector<std::uint32_t>& members : groups_) {
    std::array<double, 6> box = boxes[members.front()];
    for (const std::uint32_t b : members) {
      for (std::size_t a = 0; a < 3; ++a) {
        box[a] = std::min(box[a], boxes[b][a]);
        box[a + 3] = std::max(box[a + 3], boxes[b][a + 3]);
      }
    }
    for (const std::uint32_t b : members) boxes[b] = box;
  }
  std::vector<LocalEntry> entries;
  std::vector<std::vector<std::uint32_t>> sent_bodies(ranks);
  for (std::uint32_t b = 0; b < count; ++b) {
    if (owner[b] == rank_) {
      entries.push_back({b, nullptr, -1});
      for (std::size_t r = 0; r < ranks; ++r) {
        if (static_cast<int>(r) != rank_ && overlap(boxes[b], &regions[6 * r])) {
          sent_bodies[r].push_back(b);
        }
      }
    } else if (overlap(boxes[b], &regions[6 * static_cast<std::size_t>(rank_)])) {
      entries.push_back({b, nullptr, owner[b]});
    }
  }
  const Clock::time_point start = Clock::now();
  if (Status s = build_local(std::move(entries), sent_bodies); !s) return s;
  stats_.partition_seconds += seconds_since(start);
  return Status::ok();
}

std::vector<std::uint32_t> DistributedSimulation::owned() const {
  std::vector<std::uint32_t> out;
  for (std::size_t k = 0; k < local_bodies_.size(); ++k) {
    if (local_owned_[k] != 0) out.push_back(local_bodies_[k]);
  }
  return out;
}

Result<std::vector<Record>> DistributedSimulation::owned_records() {
  std::vector<Record> records;
  if (!local_) return records;
  Result<Snapshot> snap = local_->snapshot();
  if (!snap) return status_of(snap);
  if (Status s = local_->read_plane_impulses(snap.value()); !s) return s;
  const std::size_t planes = scene_.planes.size();
  const std::vector<BodyInfo>& infos = local_->bodies();
  for (std::size_t k = 0; k < local_bodies_.size(); ++k) {
    if (local_owned_[k] == 0) continue;
    const BodyInfo& info = infos[k];
    Record r;
    r.body = local_bodies_[k];
    r.state = {
        snap->body_pos[k],    snap->body_quat[k],
        snap->body_vel[k],    snap->body_angmom[k],
        snap->body_angvel[k], snap->body_pos_low.empty() ? vec4(0.0f) : snap->body_pos_low[k]};
    const auto p = snap->particle_pos.begin() + info.first_particle;
    const auto v = snap->particle_vel.begin() + info.first_particle;
    r.pos.assign(p, p + info.particle_count);
    r.vel.assign(v, v + info.particle_count);
    const auto q = snap->cluster_rotation.begin() + info.first_cluster;
    r.rotations.assign(q, q + info.cluster_count);
    if (!snap->plane_impulse.empty()) {
      const auto a = snap->plane_impulse.begin() + std::ptrdiff_t{info.first_particle} * planes;
      r.planes.assign(a, a + std::ptrdiff_t{info.particle_count} * planes);
    }
    records.push_back(std::move(r));
  }
  return records;
}

void DistributedSimulation::group_bodies() {
  // Union-find over the scene's bodies (then its cloths and ropes).
  const std::size_t rigid = scene_.bodies.size();
  std::vector<std::uint32_t> parent(rigid + scene_.linked.size());
  for (std::uint32_t b = 0; b < parent.size(); ++b) parent[b] = b;
  const auto find = [&](std::uint32_t b) {
    while (parent[b] != b) b = parent[b] = parent[parent[b]];
    return b;
  };
  const auto unite = [&](std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  };
  // A cloth or rope and the bodies it is attached to: the links pull on them within a substep.
  for (std::size_t l = 0; l < scene_.linked.size(); ++l) {
    for (const LinkAttachment& a : scene_.linked[l].attached) {
      for (std::uint32_t b = 0; b < rigid; ++b) {
        if (scene_.bodies[b].name == a.body) {
          unite(static_cast<std::uint32_t>(rigid + l), b);
          break;
        }
      }
    }
  }
  // With impulse or position contacts, every rigid body: an impulse iteration (a substep's
  // projection) passes velocities (poses) from body to body through every contact, as far as the
  // iterations (substeps) reach.
  if (rigid_contacts_without_forces(scene_.settings.contact_model)) {
    std::uint32_t first = UINT32_MAX;
    for (std::uint32_t b = 0; b < rigid; ++b) {
      if (scene_.bodies[b].soft) continue;
      if (first == UINT32_MAX) first = b;
      unite(first, b);
    }
  }
  // With position contacts, everything: a step is a frame of many substeps, each of several Jacobi
  // sweeps, and a particle's shift passes positions on to soft bodies, cloth, ropes and the rigid
  // bodies they touch as far as the sweeps reach, beyond any halo a step's copies could have (a
  // cloth split over two ranks differed from one process in its first frame): such a scene runs
  // on one rank.
  if (scene_.settings.contact_model == ContactModel::Positions) {
    for (std::uint32_t b = 1; b < parent.size(); ++b) unite(0, b);
  }
  // Bodies alone stay kAlone (most bodies of a large scene: no list each).
  std::vector<std::uint32_t> size(parent.size(), 0);
  for (std::uint32_t b = 0; b < parent.size(); ++b) ++size[find(b)];
  group_of_.assign(parent.size(), kAlone);
  groups_.clear();
  std::vector<std::uint32_t> index(parent.size(), kAlone);
  for (std::uint32_t b = 0; b < parent.size(); ++b) {
    const std::uint32_t root = find(b);
    if (size[root] < 2) continue;
    if (index[root] == kAlone) {
      index[root] = static_cast<std::uint32_t>(groups_.size());
      groups_.emplace_back();
    }
    group_of_[b] = index[root];
    groups_[index[root]].push_back(b);
  }
}

Status DistributedSimulation::partition(std::vector<Record> held) {
  const Clock::time_point start = Clock::now();
  const auto ranks = static_cast<std::size_t>(size_);
  // 1. Every group of bodies (a body alone, or bodies that must be stepped together: the mean of
  // its members' centres, summed in scene order) to the rank whose brick holds its centre.
  const auto by_body = [](const Record& a, const Record& b) { return a.body < b.body; };
  if (!std::is_sorted(held.begin(), held.end(), by_body)) {
    std::sort(held.begin(), held.end(), by_body);
  }
  std::unordered_map<std::uint32_t, Eigen::Vector3d> sums;  // groups of several bodies
  for (const Record& r : held) {
    const std::uint32_t g = group_of_[r.body];
    if (g != kAlone) {
      sums.try_emplace(g, Eigen::Vector3d::Zero()).first->second += centre_of(r.state[0]);
    }
  }
  // Bodies that stay are kept as they are; only those that move travel.
  std::vector<std::vector<vec4>> out(ranks);
  std::vector<Record> owned;
  std::uint64_t moved = 0;
  for (Record& r : held) {
    const std::uint32_t g = group_of_[r.body];
    const Eigen::Vector3d centre =
        g == kAlone ? centre_of(r.state[0])
                    : Eigen::Vector3d(sums.at(g) / static_cast<double>(groups_[g].size()));
    const int to = decomposition_.owner(centre);
    if (to == rank_) {
      owned.push_back(std::move(r));
    } else {
      ++moved;
      append(out[static_cast<std::size_t>(to)], r);
    }
  }
  held.clear();
  std::vector<int> counts;
  Result<std::vector<vec4>> arrived = all_to_all(comm_, out, counts);
  if (Status st = agree(comm_, status_of(arrived)); !st) return st;
  // The bodies that stayed are in order; the arrivals are sorted and merged in.
  const auto stayed = static_cast<std::ptrdiff_t>(owned.size());
  for (Record& r : parse(arrived.value())) owned.push_back(std::move(r));
  std::sort(owned.begin() + stayed, owned.end(), by_body);
  std::inplace_merge(owned.begin(), owned.begin() + stayed, owned.end(), by_body);
  std::uint64_t migrations = 0;
  MPI_Allreduce(&moved, &migrations, 1, MPI_UINT64_T, MPI_SUM, comm_);

  // 2. Halos: every owned body whose particles come within 2 margins of the particles another
  // rank owns (boxes grown by the radii) goes there as a copy.
  double mine[6];
  for (int a = 0; a < 3; ++a) {
    mine[a] = std::numeric_limits<double>::infinity();
    mine[a + 3] = -std::numeric_limits<double>::infinity();
  }
  std::vector<std::array<double, 6>> boxes;
  boxes.reserve(owned.size());
  for (const Record& r : owned) {
    boxes.push_back(record_box(r));
    for (int a = 0; a < 3; ++a) {
      mine[a] = std::min(mine[a], boxes.back()[static_cast<std::size_t>(a)] - halo_width_);
      mine[a + 3] =
          std::max(mine[a + 3], boxes.back()[static_cast<std::size_t>(a + 3)] + halo_width_);
    }
  }
  std::vector<double> all(6 * ranks);
  MPI_Allgather(mine, 6, MPI_DOUBLE, all.data(), 6, MPI_DOUBLE, comm_);
  // A group goes whole: where one member comes near, all go (grouped bodies are stepped
  // together, also as copies).
  std::vector<std::vector<std::uint32_t>> sent_bodies(ranks);
  for (auto& o : out) o.clear();
  std::unordered_map<std::uint32_t, std::array<double, 6>> group_boxes;  // groups of several
  for (std::size_t k = 0; k < owned.size(); ++k) {
    const std::uint32_t g = group_of_[owned[k].body];
    if (g == kAlone) continue;
    auto [it, fresh] = group_boxes.try_emplace(g, boxes[k]);
    for (std::size_t a = 0; a < 3 && !fresh; ++a) {
      it->second[a] = std::min(it->second[a], boxes[k][a]);
      it->second[a + 3] = std::max(it->second[a + 3], boxes[k][a + 3]);
    }
  }
  for (std::size_t k = 0; k < owned.size(); ++k) {
    const std::uint32_t g = group_of_[owned[k].body];
    const std::array<double, 6>& box = g == kAlone ? boxes[k] : group_boxes.at(g);
    for (std::size_t r = 0; r < ranks; ++r) {
      if (static_cast<int>(r) == rank_ || !overlap(box, &all[6 * r])) continue;
      append(out[r], owned[k]);
      sent_bodies[r].push_back(owned[k].body);
    }
  }
  Result<std::vector<vec4>> copies = all_to_all(comm_, out, counts);
  if (Status st = agree(comm_, status_of(copies)); !st) return st;
  // The copies arrive by source rank, each source's ascending; remember which came from whom.
  std::vector<int> source;
  std::vector<Record> halo = parse(copies.value(), &counts, &source);

  // 3. The local simulation of the owned bodies and the copies.
  std::vector<LocalEntry> entries;
  entries.reserve(owned.size() + halo.size());
  for (const Record& r : owned) entries.push_back({r.body, &r, -1});
  for (std::size_t k = 0; k < halo.size(); ++k) {
    entries.push_back({halo[k].body, &halo[k], source[k]});
  }
  if (Status s = build_local(std::move(entries), sent_bodies); !s) return s;
  stats_.migrations += migrations;
  stats_.partition_seconds += seconds_since(start);
  return Status::ok();
}

Status DistributedSimulation::build_local(
    std::vector<LocalEntry> entries, const std::vector<std::vector<std::uint32_t>>& sent_bodies) {
  const auto ranks = static_cast<std::size_t>(size_);
  // Owned bodies and copies in scene order, on the device the last simulation ran on (opened
  // once per rank).
  if (local_) spare_ = Simulation::take_device(std::move(local_));
  local_bodies_.clear();
  local_owned_.clear();
  std::sort(entries.begin(), entries.end(),
            [](const LocalEntry& a, const LocalEntry& b) { return a.body < b.body; });
  send_.assign(ranks, {});
  receive_.assign(ranks, {});
  std::uint64_t owned_bodies = 0;
  for (std::size_t k = 0; k < entries.size(); ++k) {
    local_bodies_.push_back(entries[k].body);
    local_owned_.push_back(entries[k].from < 0 ? 1 : 0);
    if (entries[k].from >= 0) {
      receive_[static_cast<std::size_t>(entries[k].from)].push_back(static_cast<std::uint32_t>(k));
    } else {
      ++owned_bodies;
    }
  }
  for (std::size_t r = 0; r < ranks; ++r) {
    // sent_bodies[r] is ascending, as the local order: map scene bodies to local indices.
    std::size_t k = 0;
    for (std::uint32_t b : sent_bodies[r]) {
      while (local_bodies_[k] != b) ++k;
      send_[r].push_back(static_cast<std::uint32_t>(k));
    }
  }
  Status built = Status::ok();
  stats_.owned_bodies = owned_bodies;
  stats_.halo_bodies = entries.size() - owned_bodies;
  stats_.owned_particles = 0;
  stats_.halo_particles = 0;
  for (auto* halves : {&send_counts_, &receive_counts_}) {
    for (std::vector<int>& c : *halves) c.assign(ranks, 0);
  }
  if (!entries.empty()) {
    Result<std::unique_ptr<Simulation>> sim = local_simulation(
        local_bodies_, send_, receive_,
        spare_ ? Result<std::unique_ptr<Device>>(std::move(spare_)) : open_device_());
    if (sim) {
      local_ = std::move(sim).value();
      device_info_ = local_->device().info();
      const std::vector<BodyInfo>& infos = local_->bodies();
      // Each rank's part of the packed halo, in vec4s: the particles' part, the bodies' part.
      const auto count = [&](const std::vector<std::vector<std::uint32_t>>& by_rank,
                             std::array<std::vector<int>, 2>& halves) {
        for (std::size_t r = 0; r < ranks; ++r) {
          for (const std::uint32_t k : by_rank[r]) {
            const BodyInfo& info = infos[k];
            halves[0][r] += static_cast<int>(MOTES_HALO_PARTICLE_VEC4S * info.particle_count);
            if (info.has_body_state()) halves[1][r] += static_cast<int>(MOTES_HALO_BODY_VEC4S);
          }
        }
      };
      count(send_, send_counts_);
      count(receive_, receive_counts_);
      for (std::size_t k = 0; k < entries.size(); ++k) {
        (entries[k].from < 0 ? stats_.owned_particles : stats_.halo_particles) +=
            infos[k].particle_count;
      }
      // The bodies' state: the scene's at the start, else their records'.
      if (entries.front().record != nullptr) built = write_records(entries);
    } else {
      built = sim.status();
    }
  }
  if (Status s = agree(comm_, built); !s) return s;
  // The bodies' part of the halo travels only where some rank has a rigid body in its halo.
  int bodies_here = 0;
  for (const int c : send_counts_[1]) bodies_here |= c != 0 ? 1 : 0;
  int bodies_anywhere = 0;
  MPI_Allreduce(&bodies_here, &bodies_anywhere, 1, MPI_INT, MPI_LOR, comm_);
  halo_bodies_ = bodies_anywhere != 0;
  ++stats_.partitions;
  return connect_halos();
}

Result<std::unique_ptr<Simulation>> DistributedSimulation::local_simulation(
    const std::vector<std::uint32_t>& bodies, const std::vector<std::vector<std::uint32_t>>& send,
    const std::vector<std::vector<std::uint32_t>>& receive,
    Result<std::unique_ptr<Device>> device) const {
  if (!device) return device.status();
  // One rank holds the whole scene: no copy of it is needed.
  if (size_ == 1) return Simulation::create(scene_, std::move(device).value());
  HaloLists lists;
  lists.scene_particles = static_cast<std::uint32_t>(particles_);
  lists.scene_diameter = scene_diameter_;
  for (std::size_t r = 0; r < send.size(); ++r) {
    lists.send.insert(lists.send.end(), send[r].begin(), send[r].end());
    lists.receive.insert(lists.receive.end(), receive[r].begin(), receive[r].end());
  }
  return Simulation::create(sub_scene(scene_, bodies), std::move(device).value(), lists);
}

Status DistributedSimulation::connect_halos() {
  direct_ = false;
  fetches_.clear();
  stats_.halo_direct = false;
  stats_.halo_host_reason.clear();
  Device* device = local_ ? &local_->device() : spare_.get();
  if (device != nullptr) device->close_peer_outboxes();
  if (size_ == 1 || halo_mode_ == DistributedOptions::Halo::Host) return Status::ok();
  if (!one_host_) {
    stats_.halo_host_reason = "the ranks run on more than one host";
    return Status::ok();
  }
  // Every rank has closed the outboxes it had opened: each may now grow its own.
  MPI_Barrier(comm_);
  constexpr std::size_t kBlock = 128;  // a handle's room: its length, then its bytes
  std::array<unsigned char, kBlock> mine{};
  Status able = Status::ok();
  if (local_) {
    Result<std::vector<unsigned char>> handle = local_->share_halo();
    if (!handle) {
      able = handle.status();
    } else if (handle->empty() || handle->size() > kBlock - 1) {
      able = Status::error(
          fmt::format("{} cannot share device memory between processes", device_info_.backend));
    } else {
      mine[0] = static_cast<unsigned char>(handle->size());
      std::copy(handle->begin(), handle->end(), mine.begin() + 1);
    }
  }
  if (Status s = agree(comm_, able); !s) {
    stats_.halo_host_reason = s.message();
    return Status::ok();
  }
  const auto ranks = static_cast<std::size_t>(size_);
  std::vector<unsigned char> handles(kBlock * ranks);
  MPI_Allgather(mine.data(), static_cast<int>(kBlock), MPI_BYTE, handles.data(),
                static_cast<int>(kBlock), MPI_BYTE, comm_);
  // Where each part for each rank starts in this rank's outbox (the packed layout of the host
  // path: every rank's particles, then every rank's bodies), and so where a neighbour's part for
  // this rank starts in its outbox.
  std::vector<std::int64_t> sent_at(2 * ranks), from(2 * ranks), received_at(2 * ranks);
  std::int64_t out = 0;
  std::int64_t in = 0;
  for (std::size_t part = 0; part < 2; ++part) {
    for (std::size_t r = 0; r < ranks; ++r) {
      sent_at[2 * r + part] = out;
      out += send_counts_[part][r];
      received_at[2 * r + part] = in;
      in += receive_counts_[part][r];
    }
  }
  MPI_Alltoall(sent_at.data(), 2, MPI_INT64_T, from.data(), 2, MPI_INT64_T, comm_);
  Status opened = Status::ok();
  for (std::size_t r = 0; r < ranks && local_ && opened; ++r) {
    const std::size_t parts = halo_bodies_ ? 2 : 1;
    std::int64_t count = 0;
    for (std::size_t part = 0; part < parts; ++part) count += receive_counts_[part][r];
    if (count == 0) continue;
    const unsigned char* block = handles.data() + kBlock * r;
    Result<std::size_t> peer =
        local_->open_peer_halo(std::vector<unsigned char>(block + 1, block + 1 + block[0]));
    if (!peer) {
      opened = peer.status();
      break;
    }
    for (std::size_t part = 0; part < parts; ++part) {
      if (receive_counts_[part][r] == 0) continue;
      fetches_.push_back({peer.value(), static_cast<std::size_t>(from[2 * r + part]),
                          static_cast<std::size_t>(received_at[2 * r + part]),
                          static_cast<std::size_t>(receive_counts_[part][r])});
    }
  }
  if (Status s = agree(comm_, opened); !s) {
    if (local_) local_->device().close_peer_outboxes();
    fetches_.clear();
    stats_.halo_host_reason = s.message();
    return Status::ok();
  }
  direct_ = true;
  stats_.halo_direct = true;
  return Status::ok();
}

Status DistributedSimulation::write_records(const std::vector<LocalEntry>& entries) {
  const std::vector<BodyInfo>& infos = local_->bodies();
  Snapshot state;
  state.step = steps_;
  state.time = time();
  state.cluster_rotation.resize(local_->sizes().clusters);
  const std::size_t n = local_->particle_count();
  const std::size_t planes = local_->sizes().impulse != 0 ? scene_.planes.size() : 0;
  state.plane_impulse.resize(n * planes);
  state.particle_pos.resize(n);
  state.particle_vel.resize(n);
  for (std::size_t k = 0; k < entries.size(); ++k) {
    const Record& r = *entries[k].record;
    std::copy(r.pos.begin(), r.pos.end(), state.particle_pos.begin() + infos[k].first_particle);
    std::copy(r.vel.begin(), r.vel.end(), state.particle_vel.begin() + infos[k].first_particle);
    state.body_pos.push_back(r.state[0]);
    state.body_quat.push_back(r.state[1]);
    state.body_vel.push_back(r.state[2]);
    state.body_angmom.push_back(r.state[3]);
    state.body_angvel.push_back(r.state[4]);
    state.body_pos_low.push_back(r.state[5]);
    if (r.rotations.size() != infos[k].cluster_count) {
      return Status::error(fmt::format("body {}: {} cluster rotations for {} clusters", r.body,
                                       r.rotations.size(), infos[k].cluster_count));
    }
    std::copy(r.rotations.begin(), r.rotations.end(),
              state.cluster_rotation.begin() + infos[k].first_cluster);
    if (r.planes.size() == std::size_t{infos[k].particle_count} * planes) {
      std::copy(r.planes.begin(), r.planes.end(),
                state.plane_impulse.begin() +
                    static_cast<std::ptrdiff_t>(std::size_t{infos[k].first_particle} * planes));
    }
  }
  return local_->write_state(state);
}

double DistributedSimulation::exchange_on_host(std::size_t out_particles,
                                               std::size_t in_particles) {
  // The packed halo in the local simulation's host memory (page-locked on CUDA), sent and
  // received in place; a rank without bodies has none to send or receive.
  const vec4* out = local_ ? local_->halo_sent().data() : nullptr;
  vec4* in = local_ ? local_->halo_received().data() : nullptr;
  const Clock::time_point start = Clock::now();
  for (std::size_t part = 0; part < (halo_bodies_ ? 2u : 1u); ++part) {
    // Particles' part from the start of each buffer, the bodies' part after it.
    const std::vector<int>& sent = send_counts_[part];
    const std::vector<int>& received = receive_counts_[part];
    std::vector<int> sent_at(sent.size()), received_at(received.size());
    int at_out = part == 0 ? 0 : static_cast<int>(out_particles);
    int at_in = part == 0 ? 0 : static_cast<int>(in_particles);
    for (std::size_t r = 0; r < sent.size(); ++r) {
      sent_at[r] = at_out;
      at_out += sent[r];
      received_at[r] = at_in;
      at_in += received[r];
    }
    MPI_Alltoallv(out, sent.data(), sent_at.data(), vec4_type(), in, received.data(),
                  received_at.data(), vec4_type(), comm_);
  }
  return seconds_since(start);
}

Result<double> DistributedSimulation::exchange_halos(Status stepped) {
  const Clock::time_point start = Clock::now();
  // Any failure on the way is kept, and this rank still takes part in every collective with
  // buffers of the agreed sizes; the last collective (agree) tells every rank.
  Status status = std::move(stepped);
  const auto total = [](const std::vector<int>& counts) {
    std::size_t sum = 0;
    for (const int c : counts) sum += static_cast<std::size_t>(c);
    return sum;
  };
  const std::size_t out_particles = total(send_counts_[0]);
  const std::size_t in_particles = total(receive_counts_[0]);
  stats_.halo_bytes += (out_particles + total(send_counts_[1])) * sizeof(vec4);
  double mpi = 0.0;  // seconds in MPI calls: the transfer, and waiting for the slowest rank
  const auto agreed = [&](double* value) {
    const Clock::time_point t = Clock::now();
    Status s = agree(comm_, status, value);
    mpi += seconds_since(t);
    return s;
  };
  if (direct_) {
    // Device to device: each rank publishes its packed halo in its outbox; once every rank has
    // (the barrier), each copies its parts from its neighbours' outboxes. A rank publishes again
    // only after the next agreement below, which every rank enters after its copies are done.
    if (local_ && status) status = local_->halo_pack_direct();
    const Clock::time_point t = Clock::now();
    MPI_Barrier(comm_);
    mpi += seconds_since(t);
    if (local_ && status) status = local_->halo_unpack_direct(fetches_);
  } else {
    if (local_ && status) status = local_->halo_pack();
    mpi += exchange_on_host(out_particles, in_particles);
    if (local_ && status) status = local_->halo_unpack();
  }
  // The lists are rebuilt on every rank at the steps one process would rebuild them: when any
  // particle anywhere has moved 0.45 skin since the last build (each rank tests its own
  // particles and the copies it received). Only then can the ranks partition again: how far any
  // particle has moved since the partition is measured on the devices, and until the next
  // rebuild none moves more than 0.45 skin from where it is now (docs/scale-out.md, "Migration").
  double pending = 0.0;
  if (local_ && status) {
    Result<NeighbourStats> lists = local_->neighbour_stats();
    if (lists) {
      pending = lists->rebuild_pending ? 1.0 : 0.0;
    } else {
      status = lists.status();
    }
  }
  if (Status s = agreed(&pending); !s) return s;
  double far = 0.0;
  if (pending > 0.0) {
    if (local_) status = local_->request_rebuild();
    if (local_ && status) {
      Result<double> moved = local_->partition_displacement();
      if (moved) {
        far = moved.value();
      } else {
        status = moved.status();
      }
    }
    if (Status s = agreed(&far); !s) return s;
    far += 0.45 * skin_;
  }
  stats_.mpi_seconds += mpi;
  stats_.copy_seconds += seconds_since(start) - mpi;
  return far;
}

Status DistributedSimulation::step(std::uint64_t count) {
  for (std::uint64_t k = 0; k < count; ++k) {
    const Clock::time_point start = Clock::now();
    Status stepped = local_ ? local_->step(1) : Status::ok();
    stats_.step_seconds += seconds_since(start);
    ++steps_;
    if (size_ == 1) {  // one rank: no halos, nothing to migrate
      if (!stepped) return stepped;
      continue;
    }
    Result<double> far = exchange_halos(std::move(stepped));
    if (!far) return far.status();
    if (far.value() > margin_) {
      Result<std::vector<Record>> records = owned_records();
      if (Status s = agree(comm_, status_of(records)); !s) return s;
      if (Status s = partition(std::move(records).value()); !s) return s;
    }
  }
  return Status::ok();
}

Result<Snapshot> DistributedSimulation::gather(int root) {
  Result<std::vector<Record>> records = owned_records();
  if (Status s = agree(comm_, status_of(records)); !s) return s;
  std::vector<vec4> mine;
  for (const Record& r : records.value()) append(mine, r);
  const int count = static_cast<int>(mine.size());
  std::vector<int> counts(static_cast<std::size_t>(size_)), at(static_cast<std::size_t>(size_));
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, root, comm_);
  std::vector<vec4> all;
  if (rank_ == root) {
    std::size_t total = 0;
    for (int r = 0; r < size_; ++r) {
      at[static_cast<std::size_t>(r)] = static_cast<int>(total);
      total += static_cast<std::size_t>(counts[static_cast<std::size_t>(r)]);
    }
    all.resize(total);
  }
  MPI_Gatherv(mine.data(), count, vec4_type(), all.data(), counts.data(), at.data(), vec4_type(),
              root, comm_);
  Snapshot s;
  s.step = steps_;
  s.time = time();
  if (rank_ != root) return s;
  const std::size_t nb = bodies_.size();
  s.particle_pos.resize(particles_);
  s.particle_vel.resize(particles_);
  s.particle_body.resize(particles_);
  s.body_pos.resize(nb);
  s.body_quat.assign(nb, vec4(0.0f, 0.0f, 0.0f, 1.0f));
  s.body_vel.resize(nb);
  s.body_angmom.resize(nb);
  s.body_angvel.resize(nb);
  s.body_pos_low.resize(nb);
  std::vector<char> seen(nb, 0);
  for (const Record& r : parse(all)) {
    const BodyInfo& info = bodies_[r.body];
    if (seen[r.body]++ != 0 || r.pos.size() != info.particle_count) {
      return Status::error(
          fmt::format("gather: body {} owned twice or with {} particles", r.body, r.pos.size()));
    }
    std::copy(r.pos.begin(), r.pos.end(), s.particle_pos.begin() + info.first_particle);
    std::copy(r.vel.begin(), r.vel.end(), s.particle_vel.begin() + info.first_particle);
    std::fill_n(s.particle_body.begin() + info.first_particle, info.particle_count, r.body);
    s.body_pos[r.body] = r.state[0];
    s.body_quat[r.body] = r.state[1];
    s.body_vel[r.body] = r.state[2];
    s.body_angmom[r.body] = r.state[3];
    s.body_angvel[r.body] = r.state[4];
    s.body_pos_low[r.body] = r.state[5];
  }
  for (std::size_t b = 0; b < nb; ++b) {
    if (seen[b] == 0) return Status::error(fmt::format("gather: body {} has no owner", b));
  }
  return s;
}

}  // namespace motes
