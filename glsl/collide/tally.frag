// Counts, over a run, the particles a pass flagged: the exact searches that walked a run of
// cells past their bound (EXACT_SCAN, collide/cells.glsl), the paths that still entered a
// collider after the bound on bounces (sim/colliders.glsl, MAX_BOUNCES; velocity .w), the
// coherent re-sort's entries out of order (fluid/order.frag). A reduction in fragment passes:
// each fragment sums a block of TALLY_BLOCK × TALLY_BLOCK texels of its source, the flags
// (component u_component above 1/2, of the first u_count texels in rows of u_size.x) in the first
// pass, the previous pass's sums (u_component < 0) after it; the last pass's one fragment adds
// its sum into the 1×1 tally with additive blending. The count stays on the GPU across steps
// and is read back once at the end of a run. (A point per particle drawn into that texel cost an
// NVIDIA H100 0.65 ms at a million particles, the points' own cost; these passes take 0.16 ms.)

uniform sampler2D u_counts;
uniform ivec2 u_size;      // texels of the source
uniform int u_count;       // texels counted, in rows of u_size.x
uniform int u_component;   // the flag's component in the first pass; -1 after it (sums in .x)

layout(location = 0) out vec4 o_count;

void main() {
    ivec2 base = ivec2(gl_FragCoord.xy) * TALLY_BLOCK;
    ivec2 last = u_size - 1;
    float sum = 0.0;
    for (int j = 0; j < TALLY_BLOCK; j++) {
        for (int i = 0; i < TALLY_BLOCK; i++) {
            ivec2 t = base + ivec2(i, j);
            // Every fetch made (clamped into the source), none behind a branch, so that the
            // block's fetches can be in flight together; the texels past the count add 0 (the
            // same sum: x + 0 = x for a sum that starts at +0).
            vec4 c = texelFetch(u_counts, min(t, last), 0);
            bool counted = t.x <= last.x && t.y <= last.y && t.y * u_size.x + t.x < u_count;
            float flag = u_component < 0 ? c.x : (c[u_component] > 0.5 ? 1.0 : 0.0);
            sum += counted ? flag : 0.0;
        }
    }
    o_count = vec4(sum);
}
