# The README's "Use it from Python", run by the tests (python/tests/test_motes.py).
import motes

scene = motes.load_scene("examples/scenes/dominoes.json")
sim = motes.Simulation(scene, backend="auto")   # or "openmp", "cuda", "vulkan"
sim.step(1000)                                  # 1000 steps of dt
positions = sim.positions()                     # (N, 3) float32 numpy array, a copy
poses = sim.body_orientations()                 # (B, 4) quaternions x, y, z, w
print(f"{sim.device['backend']}: t = {sim.time:.3f} s, "
      f"lowest particle at y = {positions[:, 1].min():.4f} m, {len(poses)} bodies")
