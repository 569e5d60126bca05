// A sprite's atlas texel (Latta §3.4.6): the sprite coordinate `coord` (as gl_PointCoord, y
// down) rotated about the centre by (cos, sin) = `rotation`, looked up in the atlas tile whose
// origin is `tile` (tile units of a 2x2 atlas); outside the tile's inscribed circle a rotated
// corner would leave the tile, so the opacity there is 0. Returns the texel's colour and
// opacity; glsl/render/particle.frag does the same inline.

vec4 sprite_texel(sampler2D atlas, vec2 coord, vec2 rotation, vec2 tile) {
    vec2 d = coord - 0.5;
    vec2 r = vec2(rotation.x * d.x - rotation.y * d.y, rotation.y * d.x + rotation.x * d.y);
    vec4 tex = texture(atlas, (tile + clamp(r + 0.5, 0.0, 1.0)) * 0.5);
    float inside = dot(r, r) <= 0.25 ? 1.0 : 0.0;
    return vec4(tex.rgb, tex.a * inside);
}
