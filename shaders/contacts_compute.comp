#version 450
// contacts_compute: every dynamic particle sums the forces of its contacts, in list order, then
// the planes (the force law). The code is shaders/contacts_compute.glsl, shared with
// contacts_compute_shift.comp (the same family with MOTES_FLAG_POSITION).
#extension GL_GOOGLE_include_directive : require
#define MOTES_CONTACT_SHIFTS 0
#include "contacts_compute.glsl"
