// Model "orca": optimal reciprocal collision avoidance (van den Berg, Guy, Lin, Manocha 2011).
//
//   neighbours   the max_neighbors nearest agents within neighbor_dist (NeighbourPath)
//   obstacles    obstacle features within time_horizon_obst * max_speed + radius (FeaturePath)
//   rule         one half-plane of permitted velocities per neighbour (each agent takes half of
//                the avoidance: the truncated velocity obstacle of horizon tau, left by the
//                smallest change u, moved by u / 2) and per obstacle feature; the linear
//                program of orca_lp.hpp picks the velocity closest to the preferred one.
//
// Obstacles differ from RVO2 on purpose: each feature (an edge as an exact segment, or a circle)
// gives the half-plane that keeps the agent on its side of a line separating it from the feature
// for time_horizon_obst: v . n >= -(d - r) / tau_obst, n the line's unit normal towards the
// agent, d the centre's distance from it: of the tangent at the nearest point and other lines
// (an edge's own line and lines through its ends; a circle's other tangents), the one that
// leaves the agent's wish the most room (steer/separating_line.hpp). The nearest tangent alone
// forbade gliding past a door post's end faster than the gap closes, and walking diagonally
// towards a wall into the door beside it, and so slowed everyone entering a door (flows through
// 0.8-2.5 m doors 0.85-1.35 /(m s) with it, 1.34-1.50 with the ends' lines: docs/validation.md).
// Any such line is collision-free for that long, needs no vertex convexity flags, and v = 0
// satisfies it when the agent overlaps nothing, so the hard obstacle planes never leave the
// program empty. Edges whose inner side holds the agent's centre are skipped (back faces: the
// nearer front edge is stricter).
//
// Contact planes (ours): ORCA's fallback for crowded agents (no velocity satisfies every plane)
// minimises the largest violation, which lets discs interpenetrate; under the backoff that turns
// into freezes that break the reciprocity the planes assume (a 40-agent circle swap deadlocked).
// So each neighbour also gives a hard plane: agent i closes at most half the gap to j along the
// line of centres in one tick, v . n_ij <= max(0, d - r - eps) / (2 dt). When both agents keep
// theirs, the centres' distance projected on n_ij stays >= r: no overlap after the tick. Zero
// satisfies every hard plane (obstacles included), so the hard set is never empty and only the
// horizon planes are relaxed. Neighbours too far to reach within a tick give no contact plane.
//
// Right of way (ours): the paper splits every avoidance half and half and builds each plane from
// the neighbours' current velocities. In a crowd that deadlocks discs that cannot overlap: in a
// door they arch (each waits for the other), and when everyone stands still no plane asks anyone
// to make room, so nobody ever moves again. So for each pair one agent goes first: one coming
// out of the goal the other heads for (out before in, sim::out_before_in: else a crowd pressing
// in towards a point everyone must touch locks in those who touched it), else, of two bound for
// different goals, the one ahead (below), else the one with less of its path left (ties: a
// seeded rank; idle agents go last, they make room). It takes
// first_share of the avoidance and may close 1 - first_share of a gap; the other takes the rest
// (the shares add up to one, so the contact guarantee holds) and avoids the first one where it
// wants to go (its preferred velocity), not where it happens to stand, in proportion to how much
// the first one is held up (1 - speed / preferred speed): a neighbour walking as it wishes shows
// its intention by its velocity already, and avoiding its wish as well would sweep a lone
// person walking against a group backwards with it. Measured on a 1.2 m door
// with 150 people, a 2.5 m four-way crossing (RVO2's Blocks, 100 agents), 100 agents swapping
// on a 10 m circle and 50 + 50 people head-on in a 4 m hallway: 0 to 45 % arrive with even
// shares and current velocities, all of them with right of way and stalemate resolution
// (src/sim/stalemate.hpp), with zero overlapping pairs throughout.
//
// The one ahead (ours): path left to different goals does not say who is in front. Of two bound
// the same way (the straight lines to their goals within 60 degrees) for different goals, whose
// headings (the unit vectors u to their waypoints) are less than 120 degrees apart, the one
// further along u_i + u_j goes first: the difference of their paths left, linearised (how much
// further each would have to walk from where the other stands). In a queue that is the one in
// front; where two must pass one door, the one nearer it. Otherwise path left decides as
// before. With path left alone, someone in a doorway bound for a far goal made way for the people
// beside the door bound for nearer ones, could not (pressed from behind) and stood, and with it
// the door: SteerSuite's fun2 (380 people 1 m wide, ten goals beyond a door 2.4 m wide) got 243,
// 232 and 262 out in 600 s on seeds 1-3, with the door empty for seconds at a time; with the
// rule all 380, by 511-540 s. Pairs bound different ways are left out: ordering them by who is
// ahead where streams cross (the shipped crossing) or converge (the circle swap) cost those
// scenes a quarter of their time (docs/steering.md).
//
// Headway (ours, opt-in with time_gap > 0): ORCA lets a queue close up into contact (every plane
// allows following a walking leader at its speed), and a packed queue then moves only as fast
// as the hard contact planes let the gaps open. With a time gap T the preferred speed is capped
// at s / T, s the spacing to the nearest neighbour ahead in the corridor of the combined width
// that goes the same way (preferred directions within 60 degrees) or stands: the collision-free
// speed model's speed rule (cfsm.cpp), applied to the wish only, so the planes still decide.
// People coming towards or across are left to the planes: they are to be passed, not followed.
// Measured on SteerSuite's 101 test cases with T = 0.5 s: 12,882 instead of 11,947 of 20,312
// agents arrive (office-complex 625 -> 1000 of 1000), but bottleneck-evacuation 20 -> 8 of 200
// and the longest stalls of the concentric circles and airport-5000 grow (docs/steering.md).
// Off by default for that reason.
//
// Stream gap (ours, on by default, 1 s): where streams meet, people keep a gap. Two streams that
// meet (head-on or crossing) pass through each other only where there are gaps, and ORCA lets
// the people behind close up into contact with the ones held up in front: four streams of 100
// meeting around a pillar (SteerSuite's 4-way-oncomming cases) pressed into one knot that let
// 70 of 400 through in 600 s. The opt-in headway above keeps gaps but everywhere, and costs a
// third to a half of the flow through doors and of the speed in one-way crowds. So the gap is
// kept only at a meeting and behind it (steer/streams.hpp: a neighbour bound for another goal
// comes towards or across, and everyone who follows someone there, breadth first through the
// queue), and relative to the one ahead: the wish is capped at its speed along the wish plus
// spacing / stream_gap, so a walking queue walks on and only an approach to someone held up
// slows down. A crowd bound for one goal (a door, the fundamental diagram's ring) is not
// touched, and neither are stalemate actions (a yield must not be held back by the people it
// steps towards). Measured (docs/steering.md): the 4-way cases over seeds 1-3 325 -> 884 and
// 188 -> 651 of 1,200 (seeds 4-6: 222 -> 571, 142 -> 477); bottleneck flows the same, the
// fundamental diagram within 0.02 m/s; mixed scenes that flowed before get a little slower.
//
// Keeping to one side (ours, on by default: the right). Two people who meet head-on both step
// aside, each to the side ORCA's cone happens to favour; in a counter-flow these choices are a
// coin toss per pair, so the streams often interleave across the width and lock in a mixed knot
// where nobody can step aside any more. Pedestrians pass on a conventional side and sort into
// lanes. So an agent that has someone coming towards it in its lane ahead (within the combined
// radii plus kSideReach to either side, whose wish is more than 120 degrees from its own: see
// steer/passing.hpp) turns its wish kSideTurn to its right (pass_side left: to its left); both
// do, so they pass each other on the same side, and people walking one way gather on one side
// of a corridor. Only for people passing each other, not converging: each one's target must lie
// behind the other, so two people closing on the same door from its two sides (an arch) are left
// alone. Measured (docs/steering.md): a two-way corridor between two rooms, 1.5-3 people/s
// from each end, 12,177 -> 16,164 arrivals over seeds 1-8 (13,170 -> 15,483 on seeds 9-16);
// head-on counter-flow 50 + 50 1,887 -> 1,998 of 2,000; doors and one-goal crowds unchanged
// within their swings. That rule looked only among the neighbours (10 within 5 m) and turned
// 10 degrees. In a block of people walking one way the ten nearest are the block's own: the
// people coming the other way were seen a metre or two off, when both streams already filled
// the width, and blocks of 100 + 100 in a 4 m hallway or 20 + 20 in a 1 m corridor still knotted
// (686 and 164 of 2,000 and 480 arrived). So the agent looks pass_look (10 m) ahead for someone
// passing, through a grid of its own (steer/passing.hpp), and turns 30 degrees: the streams move
// to their sides before they meet (2,000 of 2,000 and 480 of 480; docs/steering.md). Not within
// kTurnNearWaypoint (2 m) of a waypoint where the path bends sharply (steer::bends_sharply: more
// than 45 degrees), or of the goal: there (a corridor's mouth, a door) a turned wish pressed
// people coming out of a room against the wall beside the mouth while the other stream took the
// whole corridor (a corridor between two rooms lost a sixth of its arrivals). A route round a
// pillar bends gently at corners a metre apart, so until 2026-12-01 (no turn within 2 m of any
// waypoint) nobody kept to a side on a pillar's face, where the knots with airport-5000's longest
// stalls formed (docs/steering.md).
//
// No sweeping back (ours): avoiding a stream that goes first, ORCA's closest permitted velocity
// can point backwards, and a lone agent against a group (or a traveller crossing a queue for a
// gate) was carried back tens of metres with it: 10 m in SteerSuite's hallway-two-way, 25 m in
// not-simple-obstacle-example. People step aside or stand rather than walk backwards, so a hard
// plane keeps the component against the preferred direction at most max_retreat (0.25) times
// the preferred speed; when that leaves no way round, the agent stands and the stream, whose
// planes see it, goes round it. The preferred direction includes the stalemate actions, so a
// yield still steps back. Measured (docs/steering.md): the verification cases' longest stall
// 21.5 -> 13.9 s, airport-5000's 22.9 -> 17.2 s, not-simple-obstacle-example's 86 -> 11 s.
//
// Yielding goes first (ours): the stalemate stage (src/sim/stalemate.hpp) resolves two stalled
// agents blocking each other by having one step back for a moment. That step needs room, and
// in a packed crowd the room is behind the yielding agent, where the people often had the right
// of way over it and stood their ground: the yield went nowhere, and an arch in front of a door
// stood for good (SteerSuite's bottleneck-evacuation, 200 people heading through one door for
// ten goals: 20 got through). So an agent yielding goes first against everyone who is not: the
// people behind it make way as they would for anyone going first, and the room travels back
// through the crowd. With it 195 of the 200 get through in the 600 s.
//
// Arrival horizon (ours): the planes assume each velocity is kept for time_horizon, but an agent
// that reaches its last goal within that time stops there or leaves. Agents converging on one
// goal point stood in a ring around it for minutes, each forbidden to walk in by the people on
// the far side of the ring, whom it would only have met after arriving. So a pair's horizon is
// cut to the time the sooner of the two needs to reach its last goal at its preferred speed
// (never below one tick; the hard contact planes are unchanged). Measured on SteerSuite's 101
// test cases: bottleneck-squeeze 267 -> 1000 of 1000, office-complex 625 -> 1000 of 1000,
// 90 -> 93 cases with everyone home (docs/importers.md).
//
// An agent already overlapping a neighbour (spawned so) gets the horizon plane that separates them
// within one tick (horizon dt), as in the paper, and a contact plane that keeps them from getting
// closer. Idle agents take part with their preferred velocity (zero, or stepping off a goal
// area), so they make room. The backoff stays on as the safety net; with orca it rarely fires
// (EXPLAIN ANALYZE counts it).
#include <algorithm>
#include <bit>
#include <cmath>
#include <map>
#include <numbers>

#include "plan/access_path.hpp"
#include "sim/stages.hpp"
#include "steer/model.hpp"
#include "steer/orca_pairs.hpp"
#include "steer/orca_planes.hpp"
#include "steer/passing.hpp"
#include "steer/separating_line.hpp"
#include "steer/streams.hpp"
#include "util/rng.hpp"
#include "util/stopwatch.hpp"
#include "world/geometry.hpp"
#include "world/halfplane_lp.hpp"

namespace crowddb::steer {
namespace {

// Keeping to one side (see the top): the turn of the wish, and how near its waypoint an agent
// no longer turns (the path bends there: a corner, a door).
constexpr double kSideTurn = 30 * std::numbers::pi / 180;
constexpr double kTurnNearWaypoint = 2;  // [m]
constexpr double kStanding = 1e-100;     // [m/s] a wish below this does not look for anyone

// A row's scratch in the linear programs' loop, per thread and kept: made per chunk (128 rows),
// its two dozen vectors were as many allocations each time, grown row by row.
struct LpScratch {
  std::vector<HalfPlane> planes, soft;
  std::vector<double> ipx, ipy, ivx, ivy, ir, itau, ishare;  // agent_planes' inputs
  std::vector<uint32_t> cap_pick;                            // the neighbours that cap the wish
  std::vector<uint8_t> cap_bits;
  // The pass over the neighbours' outputs besides the inputs above (steer/orca_pairs.hpp), and
  // the rows of the list padded to whole vectors of four for its lanes.
  std::vector<double> cpx, cpy, cnx, cny;
  std::vector<uint8_t> contact, capped_by;
  std::vector<uint16_t> flags;  // per four entries (PairOut::lanes)
  std::vector<uint32_t> rows;
};
thread_local LpScratch lp_scratch;

class OrcaModel final : public Model {
 public:
  void velocities(const TickInput& in, std::span<double> vx, std::span<double> vy, Executor& ex,
                  sim::OpLog& log) override {
    const AgentTable& t = in.agents;
    const OrcaParams& p = in.cfg.steering.orca;
    const std::size_t n = t.size();
    const DiscView view = DiscView::of(t);
    near_ = {};  // until this call's lists are in

    const NeighbourMethod& nm = neighbour_method(in.cfg.access.neighbours, n);
    log.used("neighbours=" + nm.info.name);
    auto& neighbours = neighbour_paths_[nm.info.name];
    if (!neighbours) neighbours = nm.make();
    const bool obstacles = in.scene.feature_count() > 0;
    const FeatureMethod* fm =
        obstacles ? &feature_method(in.cfg.access.edges, in.scene.feature_count()) : nullptr;
    if (fm) log.used("edges=" + fm->info.name);
    const bool keep_side = p.pass_side != OrcaParams::PassSide::none;
    // Only the stream meetings and (with pass_look below neighbor_dist) keeping to a side read
    // the neighbour lists. The obstacle query and the look ahead for people passing do not: they
    // run beside the neighbour query, on the same threads (Executor::both), so that neither
    // stage's one-thread parts (a grid's placement pass, a loop's last chunk) leave the other
    // thread idle. Each is timed on its own (EXPLAIN ANALYZE); side by side, their times overlap.
    const bool passing_beside = keep_side && p.pass_look >= p.neighbor_dist;
    sim::OperatorStats neighbour_op, obstacle_op, passing_op;
    Stopwatch side_by_side;
    ex.both(
        [&] {
          Stopwatch sw;
          nb_.with_dist2 = false;  // recomputed where needed (dist2_of): 80 MB fewer at 10^6
          neighbours->run(view, {}, p.neighbor_dist, p.max_neighbors, nb_, ex, neighbour_op.query);
          near_ = {&nb_, p.neighbor_dist, p.max_neighbors};
          neighbour_op.seconds = sw.seconds();
        },
        [&] {
          Stopwatch sw;
          if (obstacles) {
            reach_.resize(n);
            ex.for_each_chunk(n, kGrain, [&](std::size_t b, std::size_t e) {
              for (std::size_t i = b; i < e; ++i)
                reach_[i] = p.time_horizon_obst * t.max_speed[i] + t.radius[i];
            });
            auto& path = feature_paths_[fm->info.name];
            if (!path) path = fm->make();
            path->run(view, reach_, in.scene, features_, ex, obstacle_op.query);
          } else {
            features_.offset.assign(n + 1, 0);
            features_.feature.clear();
            features_.dist2.clear();
          }
          obstacle_op.seconds = sw.seconds();
          if (passing_beside) {
            sw.restart();
            find_passing(in, ex, passing_op.query);
            passing_op.seconds = sw.seconds();
          }
        });
    // Only the times booked below count towards the overlap (no obstacles: none booked).
    log.side_by_side(
        neighbour_op.seconds + (obstacles ? obstacle_op.seconds : 0) + passing_op.seconds,
        side_by_side.seconds());
    log.book("ORCA neighbours", n, neighbour_op.seconds).query += neighbour_op.query;
    if (obstacles) {
      sim::OperatorStats& op = log.book("ORCA obstacles", n, obstacle_op.seconds);
      op.query += obstacle_op.query;
      if (ex.threads() > 1) op.beside = "ORCA neighbours";
    }
    if (p.stream_gap > 0) {
      sim::OperatorStats& sop = log.at("ORCA stream meetings");
      log.timed("ORCA stream meetings", n, [&] { mark_meetings(stream_view(in), streams_, ex); });
      sop.count("at or behind a meeting", streams_.count);
    }
    const std::size_t chunks = (n + kGrain - 1) / kGrain;
    if (keep_side) {
      if (!passing_beside) {
        Stopwatch sw;
        find_passing(in, ex, passing_op.query);
        passing_op.seconds = sw.seconds();
      }
      sim::OperatorStats& sop = log.book("ORCA keeping to a side", n, passing_op.seconds);
      sop.query += passing_op.query;
      if (passing_beside && ex.threads() > 1) sop.beside = "ORCA neighbours";
      if (!(p.pass_look >= p.neighbor_dist))
        sop.count("someone passing among the neighbours", passing_near_);
      if (p.pass_look > 0) sop.count("someone passing within pass_look", passing_far_);
    }
    infeasible_.assign(chunks, 0);
    const double hi_share = p.first_share, lo_share = 1 - hi_share;
    log.timed("ORCA linear programs", n, [&] {
      // Priority: agents yielding to a stalemate first, then the one with less of its path left;
      // idle agents come last.
      yielding_.resize(n);
      heading_.resize(n);
      peer_.resize(n);
      ex.for_each_chunk(n, kGrain, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
          Peer& pi = peer_[i];
          pi.remaining = in.path_left[i];
          yielding_[i] =
              t.stall_action[i] == StallAction::yield_ahead && in.tick < t.stall_until[i];
          pi.arrive = arrival_time(in, i);
          // The velocity others avoid i at when i goes first: where it wants to go, as far as it
          // is held up (1 - speed / preferred speed; see the top). Once per row, not per pair.
          double ax = t.vx[i], ay = t.vy[i];
          const double want =
              std::sqrt(in.pref_vx[i] * in.pref_vx[i] + in.pref_vy[i] * in.pref_vy[i]);
          const double held =
              want > 0 ? std::clamp(1 - std::sqrt(ax * ax + ay * ay) / want, 0.0, 1.0) : 0.0;
          ax += held * (in.pref_vx[i] - ax);
          ay += held * (in.pref_vy[i] - ay);
          pi.avoid_x = ax;
          pi.avoid_y = ay;
          pi.vx = t.vx[i];
          pi.vy = t.vy[i];
          pi.radius = t.radius[i];
          heading_[i] = sim::ahead_input(t, in.goals, i);
          uint64_t h = in.cfg.seed ^ (t.id[i] * 0x9e3779b97f4a7c15ull);
          pi.rank = splitmix64(h);
        }
      });
      ex.for_each_chunk(n, kGrain, [&](std::size_t b, std::size_t e) {
        uint64_t infeasible = 0;  // the chunk's count, written once at its end (see find_passing)
        // The thread's scratch, kept across chunks and ticks (LpScratch).
        LpScratch& sc = lp_scratch;
        auto& [planes, soft, ipx, ipy, ivx, ivy, ir, itau, ishare, cap_pick, cap_bits, cpx, cpy,
               cnx, cny, contact, capped_by, flags, rows] = sc;
        const bool lanes = pair_lanes_avx2();
        const PairColumns columns{heading_.data(), peer_.data(), yielding_.data(),
                                  in.pref_vx.data(), in.pref_vy.data()};
        for (std::size_t i = b; i < e; ++i) {
          planes.clear();
          // The next row's neighbours' right-of-way inputs, a cache line each, asked for now:
          // waiting for them was the largest stall of this loop (the LP stage -2.5 %).
          if (i + 1 < n)
            for (uint32_t a = nb_.offset[i + 1]; a < nb_.offset[i + 2]; ++a) {
              __builtin_prefetch(&heading_[nb_.row[a]]);
              __builtin_prefetch(&peer_[nb_.row[a]]);
            }
          obstacle_planes(in, i, planes);
          const double vix = t.vx[i], viy = t.vy[i];
          const uint32_t lo = nb_.offset[i];
          const std::size_t m = nb_.offset[i + 1] - lo;
          // One pass over the neighbours (steer/orca_pairs.hpp): who goes first, the contact plane
          // of those within one tick's reach (hard), the inputs of the agent planes, which are
          // built several at a time afterwards (steer/orca_planes.hpp), and the caps.
          const double reach = 2 * in.cfg.dt * t.max_speed[i];
          const double beyond = reach + kSkin + t.radius[i];
          // Grown, never shrunk: a resize per row and column (zero-filling what it adds) cost
          // more than the columns' fill.
          const std::size_t mp = (m + 3) & ~std::size_t{3};
          if (ipx.size() < mp) {
            for (auto* col : {&ipx, &ipy, &ivx, &ivy, &ir, &itau, &ishare, &cpx, &cpy, &cnx, &cny})
              col->resize(mp);
            for (auto* col : {&contact, &capped_by, &cap_bits}) col->resize(mp);
            flags.resize(mp / 4);
            cap_pick.resize(mp);
            rows.resize(mp);
          }
          // The wish, turned aside for someone passing, and who of the neighbours caps it.
          double px = in.pref_vx[i], py = in.pref_vy[i];
          if (p.pass_side != OrcaParams::PassSide::none) keep_to_side(in, i, px, py);
          const Caps caps = caps_for(in, i, px, py);
          // The neighbour's values come from its two records (a cache line each), not from a
          // dozen columns of the table.
          const PairRow row{&heading_[i], &peer_[i],   yielding_[i], t.x[i],
                            t.y[i],       t.radius[i], vix,          viy,
                            reach,        beyond,      in.cfg.dt,    p.time_horizon,
                            lo_share,     hi_share,    caps.headway, caps.gap,
                            caps.ux,      caps.uy,     caps.reach};
          const PairOut out{ipx.data(),  ipy.data(),     ivx.data(),       ivy.data(),  ir.data(),
                            itau.data(), ishare.data(),  cpx.data(),       cpy.data(),  cnx.data(),
                            cny.data(),  contact.data(), capped_by.data(), flags.data()};
          if (lanes && m > 0) {
            std::copy_n(nb_.row.data() + lo, m, rows.data());
            std::fill(rows.data() + m, rows.data() + mp, rows[m - 1]);  // (outputs dropped)
            pair_lanes(row, columns, rows.data(), mp, out);
          }
          // Four entries at a time, in list order: those the lanes left to it (out before in may
          // decide who goes first; without lanes, all) one at a time, then the contact planes
          // (hard) and the caps, from the flags' set bits.
          std::size_t capped = 0;
          for (std::size_t a0 = 0; a0 < m; a0 += 4) {
            const uint32_t valid = m - a0 >= 4 ? 0xFu : (1u << (m - a0)) - 1;
            uint32_t f = lanes ? flags[a0 / 4] : 0;
            for (uint32_t one = lanes ? f >> 12 & valid : valid; one; one &= one - 1) {
              const int l = std::countr_zero(one);
              const std::size_t a = a0 + static_cast<std::size_t>(l);
              const uint32_t j = nb_.row[lo + a];
              pair_one(row, columns, j, first(in, row, i, j), out, a);
              f = (f & ~(0x111u << l)) | uint32_t{contact[a]} << l |
                  (capped_by[a] & 1u) << (4 + l) | (capped_by[a] >> 1u) << (8 + l);
            }
            for (uint32_t c = f & valid; c; c &= c - 1) {
              const std::size_t a = a0 + static_cast<std::size_t>(std::countr_zero(c));
              planes.push_back({cpx[a], cpy[a], cnx[a], cny[a]});
            }
            for (uint32_t k = (f >> 4 | f >> 8) & valid; k; k &= k - 1) {
              const int l = std::countr_zero(k);
              cap_pick[capped] = lo + static_cast<uint32_t>(a0) + static_cast<uint32_t>(l);
              cap_bits[capped] = static_cast<uint8_t>((f >> (4 + l) & 1) | (f >> (8 + l) & 1) << 1);
              ++capped;
            }
          }
          // Padded to whole vectors of four with a neighbour far off whose planes are dropped:
          // the lanes take them all in one call (agent_plane one at a time did the tail).
          for (std::size_t a = m; a < mp; ++a) {
            ipx[a] = 1;
            ipy[a] = ivx[a] = ivy[a] = ishare[a] = 0;
            ir[a] = 0.5;
            itau[a] = 1;
          }
          retreat_plane(in, i, planes);
          const std::size_t hard = planes.size();
          // Built in a buffer of their own and appended: resizing `planes` would zero-fill them
          // first, row by row.
          if (soft.size() < mp) soft.resize(mp);
          agent_planes({ipx.data(), ipy.data(), ivx.data(), ivy.data(), ir.data(), itau.data(),
                        ishare.data()},
                       mp, in.cfg.dt, vix, viy, soft.data());
          planes.insert(planes.end(), soft.begin(), soft.begin() + static_cast<std::ptrdiff_t>(m));
          if (capped) cap_wish(in, i, caps, cap_pick.data(), cap_bits.data(), capped, px, py);
          const LpResult r = solve_velocity_lp(planes, hard, t.max_speed[i], px, py);
          infeasible += !r.feasible;
          vx[i] = r.vx;
          vy[i] = r.vy;
        }
        infeasible_[b / kGrain] = infeasible;
      });
    });
    uint64_t fallback = 0;
    for (uint64_t c : infeasible_) fallback += c;
    sim::OperatorStats& lp = log.at("ORCA linear programs");
    lp.count("infeasible (3-D fallback)", fallback);
  }

  void explain(std::ostream& os, const TickInput& in, int& step) const override {
    const OrcaParams& p = in.cfg.steering.orca;
    const std::size_t n = in.agents.size();
    const NeighbourMethod& nm = neighbour_method(in.cfg.access.neighbours, n);
    os << "  " << step++ << " ORCA neighbours    the " << p.max_neighbors
       << " nearest agents within " << explain_number(p.neighbor_dist) << " m (" << n
       << " rows)\n       access path: " << nm.info.name << " (" << nm.info.description << ")\n";
    if (in.scene.feature_count() > 0) {
      const FeatureMethod& fm = feature_method(in.cfg.access.edges, in.scene.feature_count());
      os << "  " << step++ << " ORCA obstacles     obstacle features (" << in.scene.feature_count()
         << ": circles and polygon edges) within " << explain_number(p.time_horizon_obst)
         << " s x max_speed + radius\n       access path: " << fm.info.name << " ("
         << fm.info.description << ")\n";
    }
    if (p.stream_gap > 0)
      os << "  " << step++
         << " ORCA stream meetings per row: a neighbour bound for another goal comes towards or "
            "across; then, breadth first, whoever follows someone marked (ahead, in the corridor, "
            "same way)\n";
    if (p.pass_side != OrcaParams::PassSide::none) {
      os << "  " << step++
         << " ORCA keeping to a side per row: is someone coming towards it in its lane, the two "
            "passing each other? ";
      if (!(p.pass_look >= p.neighbor_dist)) os << "Among its neighbours, ";
      if (p.pass_look > 0)
        os << (p.pass_look >= p.neighbor_dist ? "Within " : "else within ")
           << explain_number(p.pass_look)
           << " m ahead\n       access path: grid (uniform grid over positions and their "
              "headings, built per tick; the cells meeting the lane ahead, band by band)\n";
      else
        os << "only (pass_look 0)\n";
    }
    os << "  " << step++ << " ORCA linear programs per row: half-planes from neighbours (tau="
       << explain_number(p.time_horizon)
       << " s, or until the sooner of the pair arrives) and obstacles (tau_obst="
       << explain_number(p.time_horizon_obst) << " s), 2-D incremental LP towards v_pref";
    if (p.pass_side != OrcaParams::PassSide::none)
      os << " turned " << explain_number(kSideTurn * 180 / std::numbers::pi) << " deg to the "
         << (p.pass_side == OrcaParams::PassSide::right ? "right" : "left")
         << " when someone passing comes towards the agent in its lane (not within "
         << explain_number(kTurnNearWaypoint) << " m of a waypoint where its path bends more than "
         << explain_number(kSharpBend) << " deg, or of its goal)";
    if (p.time_gap > 0)
      os << " capped at spacing / " << explain_number(p.time_gap)
         << " s to the agent ahead going the same way";
    if (p.stream_gap > 0)
      os << "; where streams meet and behind, capped at v_ahead + spacing / "
         << explain_number(p.stream_gap) << " s";
    os << ", backwards at most " << explain_number(p.max_retreat) << " x pref_speed";
    os << ", 3-D fallback when infeasible\n";
  }

  NearLists near_lists() const override { return near_; }

  void rows_permuted(std::span<const uint32_t> order, Executor* ex = nullptr) override {
    for (auto& [name, path] : neighbour_paths_) path->rows_permuted(order, ex);
    // The witnesses move with their rows and are renamed (anything else costs time, not answers).
    // (Into buffers kept across reorders, as the neighbour grid's: fresh pages are dear.)
    const std::size_t n = order.size();
    std::vector<uint32_t>& new_of = witness_new_of_;
    new_of.assign(witness_.size(), PassingLookahead::kNobody);
    for (std::size_t r = 0; r < n; ++r)
      if (order[r] < new_of.size()) new_of[order[r]] = static_cast<uint32_t>(r);
    std::vector<uint32_t>& moved = witness_spare_;
    moved.assign(n, PassingLookahead::kNobody);
    const auto move = [&](std::size_t b, std::size_t e) {
      for (std::size_t r = b; r < e; ++r)
        if (order[r] < witness_.size() && witness_[order[r]] < new_of.size())
          moved[r] = new_of[witness_[order[r]]];
    };
    if (ex)
      ex->for_each_chunk(n, kGrain * 64, move);
    else
      move(0, n);
    witness_.swap(moved);
  }

 private:
  // The headways (see the head comment): caps the wish (px, py) of agent i at s / time_gap
  // (time_gap > 0), and, when i is at or behind a meeting of streams and not in a stalemate
  // action, at v_ahead + s / stream_gap, for every agent ahead of i that it follows (s the
  // spacing, v_ahead the other's speed along i's wish, at least 0). Which neighbours cap it is
  // asked in the linear programs' pass over its neighbours (their columns are at hand there:
  // a pass of its own read five columns of each neighbour again); Caps holds what that asks.
  struct Caps {
    int headway = 0, gap = 0;  // which caps apply (none: 0, 0)
    double v0 = 0, ux = 0, uy = 0;
    double reach = 0;  // v0 stream_gap + r_i: with r_j, how near one followed must be to cap
  };
  Caps caps_for(const TickInput& in, std::size_t i, double px, double py) const {
    const AgentTable& t = in.agents;
    const OrcaParams& p = in.cfg.steering.orca;
    Caps c;
    if (!(p.time_gap > 0 || (p.stream_gap > 0 && streams_.marked[i]))) return c;
    c.v0 = std::sqrt(px * px + py * py);
    if (c.v0 == 0) return c;
    c.ux = px / c.v0;
    c.uy = py / c.v0;
    c.headway = p.time_gap > 0;
    c.gap = p.stream_gap > 0 && streams_.marked[i] &&
            !(t.stall_action[i] != StallAction::none && in.tick < t.stall_until[i]);
    // (follows_within_gap's reach, w gap + r_i + r_j, summed in the same order)
    c.reach = c.v0 * p.stream_gap + t.radius[i];
    return c;
  }
  // The caps of the picked neighbours (list entries, in list order; bit 0 of `bits` headway, bit
  // 1 gap) applied to the wish.
  void cap_wish(const TickInput& in, std::size_t i, const Caps& c, const uint32_t* pick,
                const uint8_t* bits, std::size_t m, double& px, double& py) const {
    const AgentTable& t = in.agents;
    const OrcaParams& p = in.cfg.steering.orca;
    double v = INFINITY;
    for (std::size_t u = 0; u < m; ++u) {
      const uint32_t j = nb_.row[pick[u]];
      const double s = std::max(std::sqrt(dist2_of(t, i, j)) - (t.radius[i] + t.radius[j]), 0.0);
      if (bits[u] & 1) v = std::min(v, s / p.time_gap);
      if (bits[u] & 2)
        v = std::min(v, std::max(t.vx[j] * c.ux + t.vy[j] * c.uy, 0.0) + s / p.stream_gap);
    }
    if (v >= c.v0) return;
    px = c.ux * v;
    py = c.uy * v;
  }

  // Keeping to one side (see the top): turns the wish (px, py) of row i kSideTurn to the pass
  // side when find_passing saw someone passing it.
  void keep_to_side(const TickInput& in, std::size_t i, double& px, double& py) const {
    if (!turn_[i]) return;
    // Clockwise (to the right) or counter-clockwise (to the left).
    const double s = in.cfg.steering.orca.pass_side == OrcaParams::PassSide::right
                         ? std::sin(kSideTurn)
                         : -std::sin(kSideTurn);
    const double c = std::cos(kSideTurn);
    const double nx = px * c + py * s, ny = -px * s + py * c;
    px = nx;
    py = ny;
  }

  // Does row i's path bend sharply at its waypoint (dx, dy away)? The goal counts as a bend (a
  // gate, a door).
  static bool bends_there(const TickInput& in, std::size_t i, double dx, double dy) {
    const AgentTable& t = in.agents;
    const auto& route = t.route[i];
    if (route.empty()) return true;
    const Vec2 after = route.size() > 1 ? route[1]
                                        : goal_target(in.goals[t.goal[i]], t.target_x[i],
                                                      t.target_y[i], t.radius[i]);
    return bends_sharply(dx, dy, after.x - t.target_x[i], after.y - t.target_y[i]);
  }

  static PassingView passing_view(const TickInput& in) {
    const AgentTable& t = in.agents;
    return {t.x, t.y, t.radius, in.pref_vx, in.pref_vy, t.target_x, t.target_y};
  }

  // turn_[i]: does row i turn aside for someone passing it (steer/passing.hpp)? Someone within
  // pass_look ahead (through the grid), or among its neighbours; never within kTurnNearWaypoint
  // of its waypoint. A neighbour passing lies at most neighbor_dist ahead, so when pass_look
  // reaches that far the grid's answer holds the neighbours' and they need no look of their own.
  void find_passing(const TickInput& in, Executor& ex, QueryStats& stats) {
    const AgentTable& t = in.agents;
    const std::size_t n = t.size();
    const PassingView view = passing_view(in);
    const double look = in.cfg.steering.orca.pass_look;
    const bool neighbours = !(look >= in.cfg.steering.orca.neighbor_dist);
    Stopwatch sw;
    if (look > 0) lookahead_.build(view, ex);
    stats.build_seconds += sw.seconds();
    sw.restart();
    turn_.resize(n);
    witness_.resize(n, PassingLookahead::kNobody);  // rows new since the last tick: no hint
    const std::size_t chunks = (n + kGrain - 1) / kGrain;
    std::vector<uint64_t> tests(chunks, 0), near(chunks, 0), far(chunks, 0);
    ex.for_each_chunk(n, kGrain, [&](std::size_t b, std::size_t e) {
      // The chunk's counts, written once at its end: counted per row in the per-chunk arrays,
      // whose entries share cache lines with the neighbouring chunks', the threads passed the
      // lines back and forth on every row.
      uint64_t n_tests = 0, n_near = 0, n_far = 0;
      for (std::size_t i = b; i < e; ++i) {
        turn_[i] = 0;
        const double wx = in.pref_vx[i], wy = in.pref_vy[i];
        const double w = std::sqrt(wx * wx + wy * wy);
        if (!(w > kStanding)) continue;  // (a wish this small has no reliable direction)
        const double dx = t.target_x[i] - t.x[i], dy = t.target_y[i] - t.y[i];
        if (dx * dx + dy * dy < kTurnNearWaypoint * kTurnNearWaypoint && bends_there(in, i, dx, dy))
          continue;
        const double ux = wx / w, uy = wy / w;
        bool seen = false;
        if (neighbours) {
          for (uint32_t a = nb_.offset[i]; a < nb_.offset[i + 1] && !seen; ++a)
            seen = passing(view, i, nb_.row[a], ux, uy);
          n_tests += nb_.offset[i + 1] - nb_.offset[i];
          n_near += seen;
        }
        if (!seen && look > 0) {
          witness_[i] = lookahead_.find(view, i, ux, uy, look, n_tests, witness_[i]);
          if (witness_[i] != PassingLookahead::kNobody) {
            seen = true;
            ++n_far;
          }
        }
        turn_[i] = seen;
      }
      const std::size_t c = b / kGrain;
      tests[c] = n_tests;
      near[c] = n_near;
      far[c] = n_far;
    });
    passing_near_ = passing_far_ = 0;
    for (std::size_t c = 0; c < chunks; ++c) {
      stats.pair_tests += tests[c];
      passing_near_ += near[c];
      passing_far_ += far[c];
    }
    stats.rows += n;
    stats.query_seconds += sw.seconds();
  }

  StreamView stream_view(const TickInput& in) const {
    const AgentTable& t = in.agents;
    return {t.x,        t.y,        t.radius, t.goal,
            in.pref_vx, in.pref_vy, &nb_,     in.cfg.steering.orca.stream_gap};
  }

  // No sweeping back (see the head comment): v . u >= -max_retreat * pref_speed, u the unit
  // preferred direction. Zero satisfies it, so the hard set stays non-empty.
  static void retreat_plane(const TickInput& in, std::size_t i, std::vector<HalfPlane>& out) {
    const AgentTable& t = in.agents;
    const double back = in.cfg.steering.orca.max_retreat * t.pref_speed[i];
    if (back >= t.max_speed[i]) return;  // cannot bind
    const double w = length(in.pref_vx[i], in.pref_vy[i]);
    if (w == 0) return;  // no direction to keep to (idle, or on its target)
    const double ux = in.pref_vx[i] / w, uy = in.pref_vy[i] / w;
    out.push_back({-ux * back, -uy * back, ux, uy});
  }

  // Appends agent i's obstacle planes.
  void obstacle_planes(const TickInput& in, std::size_t i, std::vector<HalfPlane>& out) const {
    const AgentTable& t = in.agents;
    const StaticScene& scene = in.scene;
    const double tau = in.cfg.steering.orca.time_horizon_obst;
    const double x = t.x[i], y = t.y[i], r = t.radius[i];
    for (uint32_t a = features_.offset[i]; a < features_.offset[i + 1]; ++a) {
      const std::size_t f = features_.feature[a];
      double nx, ny, d;
      if (f < scene.circles().size()) {
        const CircleObstacle& c = scene.circles()[f];
        const double dx = x - c.x, dy = y - c.y;
        if (std::sqrt(dx * dx + dy * dy) == 0) continue;  // on its centre: the backoff keeps it out
        const SeparatingLine sl =
            separating_line(c.x, c.y, c.radius, x, y, r, tau, in.pref_vx[i], in.pref_vy[i], kSkin);
        nx = sl.nx;
        ny = sl.ny;
        d = sl.d;
      } else {
        const auto [a0, a1] = scene.edge(f);
        // Polygons are counter-clockwise: the inside is left of each edge. Back face: skip.
        const double side = (a1.x - a0.x) * (y - a0.y) - (a1.y - a0.y) * (x - a0.x);
        if (side > 0) continue;
        // The separating line that leaves the wish the most room (see the top).
        const SeparatingLine sl =
            separating_line(a0, a1, x, y, r, tau, in.pref_vx[i], in.pref_vy[i], kSkin);
        nx = sl.nx;
        ny = sl.ny;
        d = sl.d;
      }
      // v . n >= -(d - r) / tau_obst; never positive (zero stays permitted, see the top).
      const double s = -std::max(0.0, d - r - kSkin) / tau;
      out.push_back({nx * s, ny * s, nx, ny});
    }
  }

  // Seconds row i needs to reach its last goal at its preferred speed: a disc goal's arrival
  // radius, a polygon goal's edge (INFINITY when a waypoint or another goal comes first, or when
  // idle).
  static double arrival_time(const TickInput& in, std::size_t i) {
    const AgentTable& t = in.agents;
    if (standing(t.state[i]) || !t.route[i].empty() || !t.then[i].empty() || t.pref_speed[i] <= 0)
      return INFINITY;
    const Goal& g = in.goals[t.goal[i]];
    double d;
    if (g.is_polygon()) {
      d = inside_goal(g, t.x[i], t.y[i]) ? 0 : std::sqrt(dist2_to_boundary(g.area, t.x[i], t.y[i]));
    } else {
      d = std::max(0.0, length(g.x - t.x[i], g.y - t.y[i]) - g.arrival_radius);
    }
    return d / t.pref_speed[i];
  }

  // Does i (row) go before j? An agent yielding to a stalemate (see the top), then out before
  // in (sim::out_before_in), then, for two walking to different goals, the one ahead (see the top;
  // sim::ahead), then less path left, then the seeded rank (steer/orca_pairs.hpp).
  bool first(const TickInput& in, const PairRow& row, std::size_t i, std::size_t j) const {
    const int f = first_or_ask(row, heading_[j], peer_[j], yielding_[j]);
    if (f != kAsk) return f != 0;
    if (const int o = sim::out_before_in(in.agents, in.goals, i, j); o != 0) return o > 0;
    return pair_rest(row, heading_[j], peer_[j]);
  }

  NeighbourLists nb_;
  NearLists near_;  // nb_ with what it was asked, once this tick's query ran
  PassingLookahead lookahead_;
  std::vector<uint8_t> turn_;  // per row: turns aside for someone passing (find_passing)
  // Per row: the last row the grid found passing it (a hint for find, maybe many ticks old or
  // naming another row since; kNobody: none).
  std::vector<uint32_t> witness_;
  std::vector<uint32_t> witness_spare_, witness_new_of_;  // rows_permuted's, kept
  uint64_t passing_near_ = 0, passing_far_ = 0;
  FeatureLists features_;
  std::vector<double> reach_;
  std::vector<uint8_t> yielding_;
  std::vector<Peer> peer_;  // per row: what the linear programs read of it (orca_pairs.hpp)
  std::vector<sim::AheadInput> heading_;  // per row: what the one ahead reads of it
  std::vector<uint64_t> infeasible_;
  StreamMarks streams_;  // who is at or behind a meeting of streams (stream gap)
  std::map<std::string, std::unique_ptr<NeighbourPath>> neighbour_paths_;
  std::map<std::string, std::unique_ptr<FeaturePath>> feature_paths_;
};

}  // namespace

std::unique_ptr<Model> make_orca_model() {
  return std::make_unique<OrcaModel>();
}

}  // namespace crowddb::steer
