// neighbours_update: grid_build and neighbours_build when a rebuild is due, decided on the device.
// Only ever launched while stream_ is being captured (cuda_launch.cpp: flush's graphs; run_timed
// decides on the host instead): neighbours_decide sets the condition of an IF node from
// NeighbourState, and the node's body, captured on a second stream, is grid_build then
// neighbours_build.
#include "cuda_device.h"
#include "shared/neighbours.h"

namespace motes::cuda {

using shared::uint;

namespace {

__global__ void neighbours_decide_kernel(cudaGraphConditionalHandle handle,
                                         const uint* __restrict__ state) {
  cudaGraphSetConditional(handle, state[MOTES_NEIGHBOUR_REBUILD] != 0 ? 1u : 0u);
}

}  // namespace

void CudaDevice::launch_neighbours_decide(cudaGraphConditionalHandle handle) {
  neighbours_decide_kernel<<<1, 1, 0, stream_>>>(handle, buf<uint>(Buffer::NeighbourState));
}

void CudaDevice::launch_neighbours_update(const shared::StepParams& p) {
  cudaStreamCaptureStatus status = cudaStreamCaptureStatusNone;
  cudaGraph_t graph = nullptr;
  const cudaGraphNode_t* deps = nullptr;
  const cudaGraphEdgeData* edges = nullptr;
  std::size_t dep_count = 0;
  if (!check(cudaStreamGetCaptureInfo(stream_, &status, nullptr, &graph),
             "cudaStreamGetCaptureInfo")) {
    return;
  }
  if (status != cudaStreamCaptureStatusActive) {
    check(cudaErrorStreamCaptureUnsupported, "neighbours_update outside a graph capture");
    return;
  }
  cudaGraphConditionalHandle handle{};
  if (!check(cudaGraphConditionalHandleCreate(&handle, graph, 0, 0),
             "cudaGraphConditionalHandleCreate")) {
    return;
  }
  launch_neighbours_decide(handle);
  if (!check(cudaStreamGetCaptureInfo(stream_, &status, nullptr, &graph, &deps, &edges, &dep_count),
             "cudaStreamGetCaptureInfo")) {
    return;
  }
  cudaGraphNodeParams params{};
  params.type = cudaGraphNodeTypeConditional;
  params.conditional.handle = handle;
  params.conditional.type = cudaGraphCondTypeIf;
  params.conditional.size = 1;
  cudaGraphNode_t node = nullptr;
  if (!check(cudaGraphAddNode(&node, graph, deps, edges, dep_count, &params),
             "cudaGraphAddNode (conditional)")) {
    return;
  }
  if (!check(cudaStreamUpdateCaptureDependencies(stream_, &node, nullptr, 1,
                                                 cudaStreamSetCaptureDependencies),
             "cudaStreamUpdateCaptureDependencies")) {
    return;
  }
  cudaGraph_t body = params.conditional.phGraph_out[0];
  if (!check(cudaStreamBeginCaptureToGraph(body_stream_, body, nullptr, nullptr, 0,
                                           cudaStreamCaptureModeThreadLocal),
             "cudaStreamBeginCaptureToGraph")) {
    return;
  }
  std::swap(stream_, body_stream_);  // the launches below go to the body's stream
  launch_grid_build(p);
  launch_neighbours_build(p);
  std::swap(stream_, body_stream_);
  const cudaError_t launched = cudaGetLastError();
  cudaGraph_t captured = nullptr;
  const cudaError_t ended = cudaStreamEndCapture(body_stream_, &captured);
  if (check(launched, "a kernel launch in the conditional rebuild")) {
    check(ended, "cudaStreamEndCapture (conditional rebuild)");
  }
}

}  // namespace motes::cuda
