// What libmotes exports. The library is built with hidden symbols (-fvisibility=hidden); every
// public header wraps its declarations in MOTES_API_BEGIN / MOTES_API_END, which gives them
// default visibility, so that a shared libmotes.so exports exactly the public API (docs/api.md).
#pragma once

#if defined(__GNUC__) || defined(__clang__)
#define MOTES_API_BEGIN _Pragma("GCC visibility push(default)")
#define MOTES_API_END _Pragma("GCC visibility pop")
#else
#define MOTES_API_BEGIN
#define MOTES_API_END
#endif
