// Threads for the element loops of one body (issue 12 item 4: the element loops split on two
// cores, results bitwise those of one thread). DeformableWorld lends its thread pool to a body for
// the body's unconstrained step when the bodies themselves are not stepped in parallel.
#pragma once

namespace taut {

class ElementLoopRunner {
 public:
  virtual ~ElementLoopRunner() = default;
  // Threads that run chunks, the caller included.
  virtual int num_loop_threads() const = 0;
  // Calls chunk(c) once for every c in [0, num_chunks), on any of the threads in any order, and
  // returns when every call has returned. A chunk writes only its own elements' slots; sums over
  // elements are the caller's, in element order after the call.
  template <typename Chunk>
  void RunChunks(int num_chunks, Chunk& chunk) {
    RunChunksErased(
        num_chunks, [](void* c, int i) { (*static_cast<Chunk*>(c))(i); }, &chunk);
  }

 protected:
  using ChunkCall = void (*)(void* chunk, int index);
  virtual void RunChunksErased(int num_chunks, ChunkCall call, void* chunk) = 0;
};

}  // namespace taut
