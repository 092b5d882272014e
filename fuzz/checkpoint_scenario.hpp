// The scenario the checkpoint fuzzer restores into (small, with every kind of saved state: a
// source, navigation with searches in flight, goal sequences, idling arrivals). Its seeds in
// fuzz/corpus/checkpoint are bodies of real checkpoints of it (save_state() without the
// trailing 8-byte checksum, which the target appends) after 0, 7 and 40 ticks.
#pragma once

inline constexpr const char* kCheckpointScenario = R"({
  "bounds": [0, 0, 20, 10], "dt": 0.1, "seed": 5, "arrival": "idle",
  "obstacles": [{"type": "circle", "x": 10, "y": 5, "radius": 1.5}],
  "goals": [{"name": "east", "x": 18, "y": 5}, {"name": "west", "x": 2, "y": 5}],
  "agents": [{"x": 3, "y": 4, "goal": ["east", "west"]}, {"x": 3, "y": 6, "goal": "east"},
             {"x": 17, "y": 5, "goal": "west"}],
  "sources": [{"area": [1, 1, 3, 3], "rate": 2, "count": 6, "goal": "east"}],
  "navigation": {"latency": 0.3}
})";
