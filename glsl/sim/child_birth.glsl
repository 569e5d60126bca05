// The birth of a child texel (sim/children.glsl), decided in the integration pass from the
// front state alone: the texel reads its parent texel (texelFetch; no CPU read-back) and is
// born when its parent asks for it in this step:
//   at the parent's death (a burst): the first `on_death` texels of the block, at the parent's
//     last position (its state at the start of the step in which it dies);
//   on the parent's trail: trail child n (the n-th after the parent's birth, at parent age
//     n / trail_rate) goes to texel on_death + (n mod (per_parent - on_death)), at the
//     parent's position at the start of the step.
// A child starts at that position plus an offset drawn from its emitter's shape (`center` is
// relative to the parent), with inherit × the parent's velocity plus a velocity drawn from its
// cone; its life was drawn once for the texel at the start (sim/init.frag), as time stamps'.
// A birth asked of a texel whose child still lives after this step is dropped and counted in
// the texel's velocity.w (cumulative; read back once, at the end of a run).
// Included by sim/integrate.frag after its samplers and, with TIMESTAMP, timestamp_step.

struct ChildStep {
    bool born;
    vec3 x;
    vec3 v;
    float drops;
};

// How often texel `slot` of a trail of `count` texels (from `first`) is asked in a step whose
// trail births are those numbered n0 + 1 .. n1.
int trail_asks(int slot, int first, int count, int n0, int n1) {
    if (count <= 0 || slot < first || n1 <= n0) {
        return 0;
    }
    // GLSL leaves % of negative operands undefined (llvmpipe computes it unsigned): keep both
    // operands non-negative. n: the first birth numbered above n0 that falls to this texel.
    int m = slot - first;
    int n = n0 + 1 + (m + count - (n0 + 1) % count) % count;
    return n <= n1 ? 1 + (n1 - n) / count : 0;
}

ChildStep child_step(int index, vec4 p, vec4 vel) {
    ChildStep s = ChildStep(false, vec3(0.0), vec3(0.0), vel.w);
    int parent, slot;
    int c = child_of(index, parent, slot);
    if (c < 0) {
        return s;
    }
    ivec4 ch = u_child[c];
    vec4 more = u_child_more[c];
    ivec2 pt = particle_texel(parent, u_width);
    vec4 pp = texelFetch(u_position, pt, 0);
    vec4 pst = texelFetch(u_static, pt, 0);
    if (!(pp.w > 0.0) || int(pst.y) != ch.z) {
        return s;  // no live parent of this emitter's type: nothing asked
    }
    // The parent's age at the start of the step, and whether it dies in the step, computed as
    // its own pass computes them.
    // The age at the end of the step is computed as the next step will compute its age at the
    // start (from the remaining life the parent's pass writes, or the next step's time), so the
    // trail's births of consecutive steps tile: none is asked twice or skipped.
#if defined(TIMESTAMP)
    // Both ends of the step's age interval, and whether a new cycle begins, from one clock
    // (u_time and u_time_next, the next step's u_time bit for bit), as the parent's own pass
    // decides its fate: consecutive intervals tile whatever a compiler makes of the
    // arithmetic (an end written life - (life - age), to round as the next start from the
    // stored remaining life does, may be folded to age: NVIDIA's asked some births twice),
    // and a parent is seen dying once per cycle (a test of the end age against dt was true in
    // two consecutive steps for a phase on a step boundary: a second burst at the new birth).
    Stamp stamp = timestamp_step(pst, int(pst.y));
    bool dies = stamp.age >= pst.z || stamp.begins;  // its life ends, or a new cycle begins
    float age = max(stamp.start_age, 0.0);  // below 0 by rounding only, in its first step
    float end = dies ? pst.z : stamp.age;
#elif defined(LIFE)
    bool dies = pp.w - u_dt <= 0.0;
    float age = pst.z - pp.w;
    float end = dies ? pst.z : pst.z - (pp.w - u_dt);
#else
    bool dies = false;  // permanent parents
    float age = u_time - pst.x;
    float end = u_time_next - pst.x;
#endif
    int asks = 0;
    if (slot < ch.w) {
        asks = dies ? 1 : 0;
    } else if (more.x > 0.0) {
        int n0 = int(floor(age * more.x));
        int n1 = int(floor(end * more.x));
        asks = trail_asks(slot, ch.w, ch.y - ch.w, n0, n1);
    }
    if (asks == 0) {
        return s;
    }
    bool occupied = p.w > 0.0 && p.w - u_dt > 0.0;
    s.drops += float(occupied ? asks : asks - 1);
    if (occupied) {
        return s;
    }
    int type = int(more.z);
    uint rng = rng_seed(uint(index), floatBitsToUint(u_time), u_seed);
    vec3 pv = texelFetch(u_velocity, pt, 0).xyz;
    s.born = true;
    s.x = pp.xyz + spawn_position(type, rng);
    s.v = more.y * pv + spawn_velocity(type, rng);
    return s;
}
