// crisp: which declarations a shared crisp exports.
//
// crisp and crisp_bake are compiled with hidden symbols (-fvisibility=hidden,
// -fvisibility-inlines-hidden): a shared libcrisp.so exports the declarations of the public headers
// marked CRISP_API and nothing else, so an engine cannot come to depend on crisp's internals, and
// the dynamic linker resolves only the public API. In a static build the mark changes nothing.
// CRISP_HIDDEN marks what an exported class holds but does not export: the definitions of the
// private State structs (src/), whose members would otherwise be exported with their class.
#pragma once

#if defined(__GNUC__) || defined(__clang__)
#define CRISP_API __attribute__((visibility("default")))
#define CRISP_HIDDEN __attribute__((visibility("hidden")))
#else
#define CRISP_API
#define CRISP_HIDDEN
#endif
