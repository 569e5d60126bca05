// Emitters that emit (the thesis §2: "In diesem Fall sendet die Quelle der ersten Ebene keine
// Partikel aus sondern weitere Partikelquellen, die dann die zweite Ebene bilden"): where the
// child emitters' particles live. The layout is fixed by formula, as the time stamps are
// (src/scene/validate/children.rs computes it): texels below u_child_start hold the parents;
// child emitter c owns the range from u_child[c].x, in which parent texel p owns the
// u_child[c].y consecutive texels from u_child[c].x + p · u_child[c].y.
//   u_child[c]      = (first texel, texels per parent, parent type, children at the parent's death)
//   u_child_more[c] = (trail children per second, velocity inherited, own type, unused)

uniform int u_child_start;
uniform int u_children;
uniform ivec4 u_child[3];
uniform vec4 u_child_more[3];

// The child emitter of texel `index` (at or above u_child_start), or -1 past the last range;
// with its parent texel and its place in the parent's block.
int child_of(int index, out int parent, out int slot) {
    parent = 0;
    slot = 0;
    for (int c = 0; c < 3; c++) {
        if (c >= u_children) {
            break;
        }
        int k = index - u_child[c].x;
        if (k >= 0 && k < u_child_start * u_child[c].y) {
            parent = k / u_child[c].y;
            slot = k - parent * u_child[c].y;
            return c;
        }
    }
    return -1;
}
