// The CPU backend: every kernel family as OpenMP loops over the shared physics headers.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <vector>

#include "contact_inputs.h"
#include "contact_lanes.h"
#include "cpu_share.h"
#include "motes/backend/device.h"
#include "shared/impulse.h"

namespace motes::openmp {

/// Zeroed heap memory aligned for vec4 and cache lines, followed by kPadding bytes of guard
/// pattern that kernels may read (4-wide loads of vec4 arrays run past the last element) but never
/// write.
class AlignedBuffer {
 public:
  static constexpr std::size_t kPadding = 64;
  static constexpr unsigned char kGuardByte = 0xA5;
  AlignedBuffer() = default;
  explicit AlignedBuffer(std::size_t bytes);
  [[nodiscard]] std::byte* data() { return data_.get(); }
  [[nodiscard]] std::size_t size() const { return size_; }
  /// True while the padding still holds the guard pattern.
  [[nodiscard]] bool guard_intact() const;

 private:
  struct Free {
    void operator()(std::byte* p) const { ::operator delete[](p, std::align_val_t{64}); }
  };
  std::unique_ptr<std::byte[], Free> data_;
  std::size_t size_ = 0;
};

class OpenMPDevice final : public Device {
 public:
  /// threads = 0: OpenMP's default (OMP_NUM_THREADS or the number of cores). Loops over fewer
  /// than min_parallel items run on one thread (< 0: kDefaultMinParallel).
  explicit OpenMPDevice(int threads, int min_parallel = -1);

  /// Below about this many items, starting and joining threads costs more than it saves.
  static constexpr int kDefaultMinParallel = 2048;

  [[nodiscard]] const DeviceInfo& info() const override { return info_; }
  [[nodiscard]] std::uint64_t required_bytes(const Sizes& sizes) const override;
  [[nodiscard]] std::uint64_t available_bytes() const override;
  Status allocate(const Sizes& sizes) override;
  Status write(Buffer b, const void* src, std::size_t bytes) override;
  Status write_at(Buffer b, std::size_t offset, const void* src, std::size_t bytes) override;
  Status read(Buffer b, void* dst, std::size_t bytes) override;

  void enqueue(Kernel k, const shared::StepParams& p) override;

  Status synchronize() override { return Status::ok(); }
  Status check_guards() override;
  void set_timing(bool on) override { timing_ = on; }
  [[nodiscard]] KernelTimes kernel_times() const override { return times_; }
  void reset_kernel_times() override { times_ = {}; }

  [[nodiscard]] int threads() const { return threads_; }

 private:
  // One per kernel family, each in the file of its name (neighbours_update.cpp, grid_build.cpp...),
  // declared from the list in motes/backend/kernels.h; enqueue() runs them at once.
#define MOTES_FAMILY_DECLARATION(E, name, reads, writes) void name(const shared::StepParams& p);
  MOTES_KERNELS(MOTES_FAMILY_DECLARATION)
#undef MOTES_FAMILY_DECLARATION

  [[nodiscard]] bool parallel(std::int64_t items) const {
    return team_ > 1 && items >= min_parallel_;
  }
  /// For loops whose items cost about 16 times a particle's share of a light pass (an impulse
  /// particle with its contacts, ~100 ns or more): threads pay off at a 16th of the items.
  [[nodiscard]] bool parallel_heavy(std::int64_t items) const {
    return team_ > 1 && items * 16 >= min_parallel_;
  }
  /// Runs f(i) for every i in [0, n): on the team when `on`, else on this thread without entering
  /// an OpenMP region (a region that runs on one thread still costs about 0.6 us: libgomp makes
  /// it a team; a small impulse scene enters some 80 a step).
  template <typename F>
  void for_items(std::int64_t n, bool on, const F& f) const {
    if (!on) {
      for (std::int64_t i = 0; i < n; ++i) f(i);
      return;
    }
#pragma omp parallel for num_threads(team_) schedule(static)
    for (std::int64_t i = 0; i < n; ++i) f(i);
  }
  template <typename T>
  T* buf(Buffer b) {
    return reinterpret_cast<T*>(buffers_[static_cast<std::size_t>(b)].data());
  }
  /// The buffers of contacts_compute and impulses_compute (contact_inputs.h).
  [[nodiscard]] ContactInputs contact_inputs();
  /// Stable LSD radix sort of (GridBucket[i], i) into (sorted_keys_, GridOrder).
  void sort_by_bucket(std::uint32_t n, std::uint32_t key_bits);

  /// Adds the time since `start` to kernel k when timing is on.
  void record(Kernel k, std::chrono::steady_clock::time_point start);

  DeviceInfo info_;
  int threads_ = 1;  // the most threads a kernel runs on
  /// The threads the kernels run on now: threads_, or fewer while other processes keep the CPUs
  /// busy (share_; only with OpenMP's default thread count, and not with MOTES_CPU_ADAPT=0).
  int team_ = 1;
  CpuShare share_{1, false};
  std::int64_t min_parallel_ = kDefaultMinParallel;
  Sizes sizes_;
  std::vector<AlignedBuffer> buffers_;
  std::vector<std::uint32_t> sorted_keys_, keys_tmp_, ids_tmp_, histograms_;
  /// impulses_compute: the rigid particles with a contact within reach at the last counting pass,
  /// ascending, and per particle whether it has one. Positions do not move between a counting
  /// pass and its sweeps, so the sweeps visit only these: the others' impulses stay 0.
  std::vector<std::uint32_t> impulse_active_;
  std::vector<std::uint8_t> impulse_touches_;
  /// Per body (and one past the last), where its particles start in impulse_active_
  /// (impulse_runs_update makes them from it).
  std::vector<std::uint32_t> impulse_body_active_;
  void impulse_runs_update(const shared::StepParams& p);
  /// contacts_compute with MOTES_FLAG_POSITION (contacts_shift.cpp).
  void contacts_shift(const shared::StepParams& p);
  /// impulses_compute: each body's shared::impulse_body_frame, made by the counting pass.
  std::vector<shared::ImpulseBody> impulse_frames_;
  /// Each rigid particle as its impulse contacts take it (shared::contact_particle), made by
  /// particles_update with the positions (impulse contacts only), or by impulses_compute when it
  /// has not since the poses or any buffer last changed (impulse_points_ready_ false).
  std::vector<shared::vec4> impulse_points_;
  bool impulse_points_ready_ = false;
  /// impulses_compute's sweeps evaluate a contact of two dynamic rigid particles once, at the
  /// lower id, for both: per list slot k of particle i (k N_r + i), the slot of i in its partner's
  /// list (kNoMirror: none, the particle evaluates it itself), made at the first counting pass
  /// after the lists changed (emptied by neighbours_build, allocate and a write to the lists);
  /// and each slot's contact impulse of the sweep (w: counted).
  std::vector<std::uint32_t> impulse_mirror_;
  std::vector<shared::vec4> impulse_pair_;
  /// contacts_compute evaluates a contact of two particles that list each other once
  /// (contact_pairs.cpp), made at the first contacts_compute after the lists changed
  /// (contact_pairs_ready_ false: neighbours_build, allocate, a write to the lists). Each list
  /// slot's term lives in contact_slot_force_, particle i's from contact_slot_first_[i]; a pair
  /// writes both its slots, a slot no pair covers (contact_own_slots_) is evaluated by its
  /// particle.
  static constexpr std::uint32_t kNoPair = 0xffffffffu;
  struct ContactPair {
    std::uint32_t a, b, slot_a, slot_b;  ///< the ids (a < b) and their slots' places
  };
  struct ContactSlot {
    std::uint32_t i, k;  ///< particle i's list slot k
  };
  bool contact_pairs_ready_ = false;
  std::vector<std::uint32_t> contact_slot_first_;
  std::vector<ContactPair> contact_pair_list_;
  std::vector<ContactSlot> contact_own_slots_;
  std::vector<shared::vec3> contact_slot_force_;  ///< 12 B a slot (vec4: 4% slower dense)
  /// Makes the pairs for these lists; false when the slots do not fit 32-bit places.
  bool contact_pairs_index(const ContactInputs& in, std::size_t n, std::uint32_t capacity);
  /// contact_pairs_index, and false (every particle then evaluates its own contacts) when there
  /// is no memory for it.
  bool share_pairs(const ContactInputs& in, std::size_t n, std::uint32_t capacity);
  /// Every slot's term: the pairs' and the own slots'; returns the slots whose term is not 0.
  std::uint64_t contact_slots_compute(const shared::StepParams& p, const ContactInputs& in);
  /// The last contacts_compute's list entries within capacity, and those that touched: it shares
  /// pairs when at least half touched.
  std::uint64_t contact_touching_ = 0, contact_entries_ = 0;
  /// Per particle, the planes it may touch before the next list build (bit k: plane k), from
  /// where the lists were built (plane_masks.cpp); made at the first contacts_compute after a
  /// build, an allocate or any write (plane_masks_ready_ false).
  std::vector<std::uint32_t> plane_masks_;
  bool plane_masks_ready_ = false;
  bool plane_masks_on_ = true;  ///< MOTES_OPENMP_PLANE_MASKS=0: every particle tests every plane
  /// The masks for these lists, or nullptr: every particle tests every plane (more than 32
  /// planes, no memory for them, or MOTES_OPENMP_PLANE_MASKS=0).
  const std::uint32_t* plane_masks(const shared::StepParams& p, const shared::vec4* ref);
  enum class SharedPairs : std::uint8_t { Auto, Never, Always };
  SharedPairs shared_pairs_ = SharedPairs::Auto;  ///< MOTES_OPENMP_SHARED_PAIRS
  /// True when the law of materials a and b is the law of b and a (the table of
  /// core/src/contact_laws.cpp always is; a buffer written by hand need not be).
  static bool laws_symmetric(const shared::ContactLaw* laws, std::uint32_t materials);
  /// impulses_sweep.cpp: a contact within reach at the last counting pass (its numbers in
  /// impulse_blocks_); bodies a and b (b == the body count: a plane); the slots of its
  /// accumulated impulse in ContactImpulse (kNone: none, it starts from 0 every sweep).
  struct ImpulseContact {
    std::uint32_t a, b, slot, mirror;
  };
  /// The counting pass and the sweeps from kept contact frames (impulses_sweep.cpp): false when
  /// they cannot be kept (a touching particle beyond its list's capacity), and impulses_compute
  /// evaluates every contact itself.
  bool impulses_count_kept(const shared::StepParams& p);
  bool impulses_sweep(const shared::StepParams& p);
  bool impulse_contacts_build(const shared::StepParams& p, bool counting);
  void impulse_bodies_update(const shared::StepParams& p);
  void impulse_contacts_solve(const shared::StepParams& p);
  /// The substep's contacts (built by the counting pass or else its first sweep, dropped when
  /// the particles move or a buffer is written), and per active particle its contacts in order
  /// (index * 2 + 1: the higher id's side of a pair), from impulse_entry_first_[a]; each body as
  /// the pass sees it (impulse_body_state), then a plane; a slot's contact while the list is
  /// built. The contacts' numbers in lanes (contact_lanes.h), kContactLanes to a block: their
  /// frames from the build, their responses from the first sweep; their accumulated impulses
  /// live there through the substep's passes (pending) and go back to ContactImpulse
  /// (impulse_acc_flush) before anything else runs or reads the buffers.
  std::vector<ImpulseContact> impulse_contacts_;
  std::vector<std::uint32_t> impulse_entries_, impulse_entry_first_, impulse_slot_contact_;
  std::vector<shared::ImpulseBody> impulse_bodies_;
  std::vector<float> impulse_velocities_[6];  // the bodies' velocities now, a component each
  std::vector<ContactBlock> impulse_blocks_;
  bool impulse_contacts_ready_ = false, impulse_responses_ready_ = false;
  bool impulse_acc_pending_ = false;
  /// Where the lanes' accumulated impulses go back to (split impulses, MOTES_FLAG_IMPULSE_SPLIT):
  /// ContactImpulse, both it and ContactImpulseSplit (after the last relaxing sweep), or
  /// ContactImpulseSplit (after a correcting sweep; ContactImpulse then takes the relaxed ones
  /// kept in impulse_acc_relaxed_ when impulse_acc_relaxed_pending_).
  enum class AccInto : std::uint8_t { Main, Both, Split };
  AccInto impulse_acc_into_ = AccInto::Main;
  std::vector<shared::vec4> impulse_acc_relaxed_;
  bool impulse_acc_relaxed_pending_ = false;
  void impulse_acc_flush();
  void impulse_acc_keep_relaxed();
  /// Drops what the last counting pass found (after allocate, or a write of positions or lists):
  /// the next sweep without a counting pass visits every particle.
  void forget_impulse_passes();
  /// What a write of buffer b makes stale: the kept contact frames and points, the impulse
  /// mirror of the lists, the last counting pass.
  void wrote(Buffer b);
  bool timing_ = false;
  KernelTimes times_;
};

/// Describes the CPU device without opening it (for `motes devices`).
DeviceInfo describe(int threads);

}  // namespace motes::openmp
