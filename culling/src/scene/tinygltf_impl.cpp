// The one translation unit that compiles Debian's tinygltf (libtinygltf-dev
// ships the header; compiling it here rather than linking libtinygltf.so lets
// the sanitizer and fuzzing builds instrument the parser too). Image decoding
// and writing are left out: culling reads geometry, lights and cameras only.
// TINYGLTF_NO_STB_IMAGE(_WRITE) and TINYGLTF_NO_EXTERNAL_IMAGE are set for the
// whole library (culling/CMakeLists.txt): they change the TinyGLTF class.
#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>
