#version 450
// contacts_compute with MOTES_FLAG_POSITION (a pass of the contacts_compute family): every
// dynamic particle sums the shifts its position contacts ask of it, with their number in w
// (shared/particle_shift.h), in the order of contacts_compute. The code is
// shaders/contacts_compute.glsl.
#extension GL_GOOGLE_include_directive : require
#define MOTES_CONTACT_SHIFTS 1
#include "contacts_compute.glsl"
