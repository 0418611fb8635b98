// contact_skipped of shared/links.h in GLSL (a function cannot take a buffer there): whether the
// particles i and j, with ParticleBody words body_i and body_j, never touch. Used by
// neighbours_build and by contacts_compute's grid walk. Needs kernel_common.glsl and
// shared/links.h.
#ifndef MOTES_LINK_EXCLUSIONS_GLSL
#define MOTES_LINK_EXCLUSIONS_GLSL

bool contact_skipped(uint body_i, uint body_j, uint i, uint j) {
  if (contact_excluded(body_i, body_j)) {
    return true;
  }
  if (!contact_listed(body_i, body_j)) {
    return false;
  }
  uint lists = p.particle_count - p.linked_first + 1u;
  uint end = link_exclusions[i - p.linked_first + 1u];
  for (uint e = link_exclusions[i - p.linked_first]; e < end; ++e) {
    uint k = link_exclusions[lists + e];
    if (k >= j) {
      return k == j;
    }
  }
  return false;
}

#endif  // MOTES_LINK_EXCLUSIONS_GLSL
