// A time stamp's birth (UberFlow §4.1), shared by the step that begins its cycle
// (sim/integrate.frag) and by the initial state for a cycle that begins at time 0
// (sim/init.frag), so that both place it alike: its place and velocity from its emitter, drawn
// from `rng` (the stream of its generation).
#ifdef RELEASE_SPREAD
uniform vec4 u_release_spread[4];   // (box size, slots per side) per type
uniform vec4 u_release_cloud;       // texels per cloud per type; 0: a cloud is a release
#endif

void stamp_birth(int type, uint index, float phase, inout uint rng, out vec3 x0, out vec3 v0) {
    x0 = spawn_position(type, rng);
    v0 = spawn_velocity(type, rng);
#ifdef RELEASE_SPREAD
    // A release is every particle of this phase (one step's births). Release k of the cycle
    // lands as a whole in slot k of a grid of side^3 slots over the box, so that releases
    // alive at once never share a place (UberFlow §5: sets that do not mix).
    // With a cloud size, every run of that many consecutive texels is a cloud of its own.
    vec4 spread = u_release_spread[type];
    int side = int(spread.w);
    int cloud = int(u_release_cloud[type]);
    int k = cloud > 0 ? int(index) / cloud : int(floor(phase / u_dt));
    // Consecutive places step along z, the slowest axis of the lattice's cell index, so the
    // clouds that share a row keep apart in a row sorted by cell.
    vec3 slot = vec3((k / (side * side)) % side, (k / side) % side, k % side);
    x0 += ((slot + 0.5) / float(side) - 0.5) * spread.xyz;
#endif
}
