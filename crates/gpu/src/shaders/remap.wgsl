// Remapping and the visibility check: a mirror of `Remapper::remap` with
// `Precision::F32Composed`, `remap_color_pixel`, `depth_slope`, `classify` and
// `occlusion_pixel` (src/effects/remap.rs, occlusion.rs).
// input0 = this eye (depth; color unused), input1 = the other eye (color for remap, depth for
// visibility).
// params[0..4]: columns of MVP_other · MVP_this⁻¹, composed in f64 on the host, rounded to f32.
// params[4]: (mode, DEPTH_PRECISION, near depth, far depth); mode 0 = remap color, 1 = occlusion.
// params[5..9]: colors background, out of view, occluded, farther (0..1).

const MODE_REMAP: f32 = 0.0;

// Where this pixel lands in the other eye: (x_win, y_win, ndc z) of the other eye, or w ≤ 0
// (behind the other eye) signalled by x = NaN.
struct Landing {
    ok: bool,
    texel: vec2<i32>,
    inside: bool,
    ndc_z: f32,
}

fn remap(pos: vec4<f32>, depth: f32) -> Landing {
    let size = vec2<f32>(textureDimensions(input0_depth));
    // pos.xy is the pixel center x + ½, y + ½, as the CPU's `x as f32 + 0.5`.
    let ndc = vec4<f32>(2.0 * pos.x / size.x - 1.0, 1.0 - 2.0 * pos.y / size.y, 2.0 * depth - 1.0, 1.0);
    // glam's `Mat4 * Vec4`: ((c0·x + c1·y) + c2·z) + c3·w.
    var clip = params[0] * ndc.x;
    clip = clip + params[1] * ndc.y;
    clip = clip + params[2] * ndc.z;
    clip = clip + params[3] * ndc.w;
    var l: Landing;
    l.ok = clip.w > 0.0;
    if !l.ok {
        return l;
    }
    let n = vec3<f32>(clip.x / clip.w, clip.y / clip.w, clip.z / clip.w);
    // τ = ½(n + 1), window = (τ.u·W, (1 − τ.v)·H), nearest texel = floor.
    let win = vec2<f32>(0.5 * (n.x + 1.0) * size.x, (1.0 - 0.5 * (n.y + 1.0)) * size.y);
    let t = floor(win);
    l.inside = t.x >= 0.0 && t.y >= 0.0 && t.x < size.x && t.y < size.y;
    l.texel = vec2<i32>(t);
    l.ndc_z = n.z;
    return l;
}

fn depth_at(p: vec2<i32>) -> f32 {
    return textureLoad(input0_depth, p, 0).r;
}

// `depth_slope`: per axis the smaller one-sided difference, summed over x and y.
fn one_sided(c: f32, a: f32, has_a: bool, b: f32, has_b: bool) -> f32 {
    if has_a && has_b {
        return min(abs(a - c), abs(b - c));
    }
    if has_a {
        return abs(a - c);
    }
    if has_b {
        return abs(b - c);
    }
    return 0.0;
}

fn depth_slope(p: vec2<i32>) -> f32 {
    let size = vec2<i32>(textureDimensions(input0_depth));
    let c = depth_at(p);
    let gx = one_sided(c, depth_at(max(p - vec2<i32>(1, 0), vec2<i32>(0))), p.x > 0,
                          depth_at(min(p + vec2<i32>(1, 0), size - 1)), p.x + 1 < size.x);
    let gy = one_sided(c, depth_at(max(p - vec2<i32>(0, 1), vec2<i32>(0))), p.y > 0,
                          depth_at(min(p + vec2<i32>(0, 1), size - 1)), p.y + 1 < size.y);
    return gx + gy;
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> FullscreenOut {
    let p = texel(pos);
    let d = depth_at(p);
    var out: FullscreenOut;
    out.depth = 0.0;
    if d >= 1.0 {
        out.color = params[5]; // background
        return out;
    }
    let l = remap(pos, d);
    if !(l.ok && l.inside) {
        out.color = params[6]; // out of view
        return out;
    }
    if params[4].x == MODE_REMAP {
        out.color = textureLoad(input1_color, l.texel, 0);
        return out;
    }
    // `classify`: other depth − remapped depth (½ n.z + ½), written (other − ½) − ½ n.z: the
    // first difference and the halving are exact, so only the last subtraction rounds.
    let other = textureLoad(input1_depth, l.texel, 0).r;
    let diff = (other - 0.5) - 0.5 * l.ndc_z;
    let tolerance = params[4].y + depth_slope(p);
    if abs(diff) <= tolerance {
        // `occlusion_pixel` for a point both eyes see: lighter the nearer.
        let near = params[4].z;
        let span = max(params[4].w - near, 1.17549435e-38);
        let t = clamp((d - near) / span, 0.0, 1.0);
        let g = floor(220.0 - 130.0 * t + 0.5) / 255.0;
        out.color = vec4<f32>(g, g, g, 1.0);
    } else if diff < 0.0 {
        out.color = params[7]; // occluded
    } else {
        out.color = params[8]; // farther
    }
    return out;
}
