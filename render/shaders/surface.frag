#version 300 es
// Ray caster of the metaball iso-surfaces (DESIGN.md, Renderer; render/surface_renderer.h describes the
// textures). Everything runs in grid units (one unit = one cell; the grid is axis-aligned with cubic
// cells, so world directions are grid directions).
//
// Per pixel: clip the ray to the box of nodes; march the union field one cell at a time, jumping over
// empty space with the blocks' distance map; refine the first crossing by bisection; shade by phase:
//   solid  opaque neutral grey: Lambert + hemispheric ambient;
//   ice    Fresnel reflection over a milky pale blue: light scattered inside, in front of what lies
//          behind, both weighted by Beer-Lambert extinction along the path through the ice;
//   water  the same with little scattering and a stronger, bluer absorption: clear and tinted.
//   glass  (solids of a transparent material) Fresnel reflection, a faint haze, and the rest of the light
//          passing on through the wall, tinted by Beer-Lambert along the path inside it: the ray goes on
//          to what the glass holds, through up to kGlassLayers walls.
// Translucent phases show what lies behind them along the straight ray (no refraction), shaded opaque.
// Coloured by a substance (THAW_TINT): the water holding it absorbs by Beer-Lambert in proportion to the
// concentration along the path, so it takes the substance's colour, deeper where there is more of it; a
// coating stains the solids and ice it sticks to toward that colour.
// Dryers are drawn over the scene: a dark nozzle, and while one blows a faint warm cone of its reach,
// hidden behind the first opaque surface, so aiming shows. Lamps are their emitting rectangles, glowing
// on their emitting side while on.
// Contact cues: ambient occlusion from the fields along the normal, and soft shadows from the blocks'
// precomputed light transmittance.
//
// llvmpipe runs this on the CPU, a group of pixels in lock-step: a loop costs its longest lane, and
// both sides of a divergent branch run. Hence the refinement after the loop, not in it, and few
// fetches per hit.
precision highp float;
precision highp int;
precision highp sampler3D;

uniform sampler3D u_field;   // max of the phases, linear
uniform sampler3D u_phases;  // ice, water, solid, glass in [0, 1], linear
uniform sampler3D u_blocks;  // per block: skip distance, fraction inside, light transmittance
uniform sampler3D u_tint;    // THAW_TINT: dye (concentration / reference in water), stain (deposit / capacity)
uniform vec3 u_dye_absorption;  // per grid length, at the reference concentration
uniform vec3 u_stain_colour;
uniform int u_has_volume;
uniform vec3 u_nodes;        // nodes per axis
uniform vec3 u_block_count;  // blocks per axis
uniform float u_block;       // cells per block along an axis
uniform float u_iso;
uniform float u_scale;       // 1 / cells along the longest axis: optical depths are per grid length
uniform vec3 u_eye;          // grid units
uniform vec3 u_forward, u_right, u_up;
uniform vec2 u_viewport;
uniform vec3 u_light;        // unit vector toward the key light
// Hair dryers (grid units): nozzle position, unit direction, and (nozzle radius, tan of the half-angle,
// reach, 1 while blowing).
uniform int u_dryers;
uniform vec3 u_dryer_pos[4];
uniform vec3 u_dryer_dir[4];
uniform vec4 u_dryer_shape[4];
// Lamps (grid units): the emitting rectangle's centre and half-axes, and its glow (0 when off).
uniform int u_lamps;
uniform vec3 u_lamp_centre[4];
uniform vec3 u_lamp_u[4];
uniform vec3 u_lamp_v[4];
uniform vec3 u_lamp_glow[4];

out vec4 o_colour;

#ifndef THAW_SEE_BEHIND
#define THAW_SEE_BEHIND 1  // 1: find and shade the surface behind ice and water (SurfaceRenderer::Quality)
#endif
#ifndef THAW_GLASS
#define THAW_GLASS 1  // 1: the fields have glass (SurfaceRenderer picks the variant per frame)
#endif
#ifndef THAW_SOURCES
#define THAW_SOURCES 1  // 1: dryers and lamps are drawn
#endif
#ifndef THAW_TINT
#define THAW_TINT 0  // 1: the water is dyed and the solids stained by the u_tint texture
#endif
const int kMaxSteps = 1024;    // march iterations (jumps and steps)
const int kBisections = 5;     // 1/32 cell
const int kMaxInside = 128;    // steps through ice or water
const float kInsideStep = 3.0;  // cells; absorption needs the path length, not every detail of it

// Optical constants per grid length (the longest axis): a body a third of the grid across is clearly
// tinted, a thin film nearly clear, whatever the scene's size in metres.
const vec3 kIceColour = vec3(0.82, 0.91, 0.98);
const float kIceScattering = 6.0;
const float kIceMinScatter = 0.35;  // thin ice still reads as ice, not glass
const vec3 kIceAbsorption = vec3(2.0, 0.8, 0.35);
const vec3 kWaterColour = vec3(0.08, 0.30, 0.52);
const float kWaterScattering = 1.5;
const vec3 kWaterAbsorption = vec3(4.5, 1.6, 0.6);
const vec3 kSolidColour = vec3(0.56, 0.56, 0.54);
// Fresnel reflectance at normal incidence, ((n - 1) / (n + 1))^2 with n = 1.31 (ice), 1.33 (water),
// 1.5 (glass).
const float kIceF0 = 0.018;
const float kWaterF0 = 0.020;
const float kGlassF0 = 0.040;
// Soda-lime glass is faintly green: clear through a wall, green along one seen edge-on.
const vec3 kGlassAbsorption = vec3(1.0, 0.3, 0.6);
const vec3 kGlassColour = vec3(0.80, 0.88, 0.86);
const float kGlassHaze = 0.025;
const int kGlassLayers = 4;   // glass surfaces a ray passes: into and out of a glass's two walls
const int kMaxGlass = 48;     // cells through one glass wall

vec3 tex_coord(vec3 g) { return (g + 0.5) / u_nodes; }
float field(vec3 g) { return texture(u_field, tex_coord(g)).r; }
vec4 phases(vec3 g) { return texture(u_phases, tex_coord(g)); }
#if THAW_TINT
float dye(vec3 g) { return texture(u_tint, tex_coord(g)).r; }
// How stained a solid or ice surface is at g, where its own field reads `own`: the stain field is the deposit
// share times the volume fraction, so the ratio is the share.
vec3 stained(vec3 base, vec3 g, float own) {
  float share = clamp(texture(u_tint, tex_coord(g)).g / max(own, 0.25), 0.0, 1.0);
  return mix(base, u_stain_colour * 0.9, 0.85 * share);
}
#else
float dye(vec3 g) { return 0.0; }
vec3 stained(vec3 base, vec3 g, float own) { return base; }
#endif
// Block b's texel centre lies at the centre of its cells, (b + 0.5) * u_block.
vec4 coarse(vec3 g) { return texture(u_blocks, g / (u_block * u_block_count)); }

// 0 = ice, 1 = water, 2 = solid, 3 = glass: the phase with the largest field.
int dominant(vec4 ph) {
  if (ph.a > ph.b && ph.a >= ph.r && ph.a >= ph.g) return 3;
  if (ph.b >= ph.r && ph.b >= ph.g) return 2;
  return ph.r >= ph.g ? 0 : 1;
}

// Neutral grey, lighter above the horizon: no colour of its own to confuse with ice or water.
vec3 background(vec3 d) {
  return mix(vec3(0.30, 0.31, 0.33), vec3(0.84, 0.85, 0.87), smoothstep(-0.7, 0.9, d.z));
}

// The parameter interval of the ray inside the box of nodes; x > y when it misses.
vec2 clip_to_box(vec3 o, vec3 inv) {
  vec3 ta = -o * inv, tb = (u_nodes - 1.0 - o) * inv;
  vec3 lo = min(ta, tb), hi = max(ta, tb);
  return vec2(max(max(lo.x, lo.y), max(lo.z, 0.0)), min(min(hi.x, hi.y), hi.z));
}

// The first t in [t0, t1] where the union field reaches iso, or -1. In a block at Chebyshev distance k
// from any block with surface, the cube of blocks within k - 1 of it is empty: jump to where the ray
// leaves that cube. Elsewhere step one cell.
float first_hit(vec3 o, vec3 d, vec3 inv, float t0, float t1) {
  float t = t0;
  if (field(o + t * d) >= u_iso) return t;
  vec3 forward = step(0.0, d);
  float hi = -1.0;
  for (int i = 0; i < kMaxSteps; ++i) {
    if (t >= t1) break;
    vec3 b = clamp(floor((o + t * d) / u_block), vec3(0.0), u_block_count - 1.0);
    float k = texelFetch(u_blocks, ivec3(b), 0).r;
    if (k > 0.0) {
      // The push past the face keeps rounding from landing back inside the cube.
      vec3 far = ((b + forward * (2.0 * k - 1.0) - (k - 1.0)) * u_block - o) * inv;
      t = max(min(min(far.x, far.y), far.z), t) + 1e-3;
      continue;
    }
    float tn = min(t + 1.0, t1);
    if (field(o + tn * d) >= u_iso) {
      hi = tn;
      break;
    }
    t = tn;
  }
  if (hi < 0.0) return -1.0;
  float lo = t;
  for (int k = 0; k < kBisections; ++k) {
    float m = 0.5 * (lo + hi);
    if (field(o + m * d) >= u_iso)
      hi = m;
    else
      lo = m;
  }
  return hi;
}

// Outward unit normal, minus the field gradient, from four samples on a tetrahedron's corners instead
// of six central differences (same first-order accuracy; Quilez, "normals for an SDF").
vec3 outward_normal(vec3 p, vec3 d) {
  const vec2 e = vec2(1.0, -1.0);
  vec3 g = e.xyy * field(p + e.xyy) + e.yyx * field(p + e.yyx) + e.yxy * field(p + e.yxy) +
           e.xxx * field(p + e.xxx);
  float len = length(g);
  return len > 1e-6 ? -g / len : -d;
}

// Ambient occlusion: how much of the space just outside the surface, along the normal, is inside some
// phase. Near contacts (ice on a floor) the normal runs into the other body; the far sample reads the
// blocks' inside fraction, a wider neighbourhood.
float occlusion(vec3 p, vec3 n) {
  float near = smoothstep(u_iso - 0.05, u_iso + 0.05, field(p + n * 2.5));
  float far = coarse(p + n * 2.0 * u_block).g;
  return clamp(1.0 - 0.45 * near - 0.55 * far, 0.0, 1.0);
}

// Transmittance toward the light, read a block off the surface so a body does not shadow itself where
// it faces the light.
float shadow(vec3 p, vec3 n) { return coarse(p + n * u_block).b; }

vec3 ambient(vec3 n) { return mix(vec3(0.55), vec3(1.0), 0.5 + 0.5 * n.z); }

vec3 diffuse(vec3 base, vec3 n, float ao, float sh) {
  return base * (0.38 * ambient(n) * ao + 0.72 * max(dot(n, u_light), 0.0) * sh);
}

vec3 lit(vec3 base, vec3 p, vec3 n) { return diffuse(base, n, occlusion(p, n), shadow(p, n)); }

float schlick(float f0, vec3 n, vec3 d) {
  return f0 + (1.0 - f0) * pow(1.0 - clamp(dot(n, -d), 0.0, 1.0), 5.0);
}

// The surface normal where the ray first meets the grid at t: a phase cut by the box has the face the
// ray came in through as its surface.
vec3 normal_at(vec3 p, vec3 d, vec3 inv, vec2 span, float t) {
  if (t == span.x && span.x > 0.0) {
    vec3 lo = min(-u_eye * inv, (u_nodes - 1.0 - u_eye) * inv);
    vec3 n = -sign(d) * step(span.x - 1e-4, lo);
    return length(n) > 0.0 ? normalize(n) : -d;
  }
  return outward_normal(p, d);
}

// The colour of an opaque solid, ice or water (phase 0, 1, 2) hit at t with normal n.
vec3 shade(vec3 p, vec3 n, vec3 d, vec3 inv, vec2 span, float t, int phase) {
  float ao = occlusion(p, n), sh = shadow(p, n);
  if (phase == 2) return diffuse(stained(kSolidColour, p, phases(p).b), n, ao, sh);

  // Walk through ice and water to their far side, or to a solid inside them, summing the path in each.
  // One RGBA8 fetch per step tells the phases apart. The exit is then refined by bisection (after the
  // loop, as in first_hit): a path quantised to whole steps shows as contour bands.
  float path_ice = 0.0, path_water = 0.0, w = phase == 0 ? 1.0 : 0.0;  // w: the ice share of the medium
  float path_dye = 0.0;  // the dye's concentration over its reference, integrated along the path
  float water_in_front = -1.0;  // the water path before the ray first meets ice inside the medium
  float tb = t, tn = t;
  bool left = false;
  for (int i = 0; i < kMaxInside; ++i) {
    tn = min(tb + kInsideStep, span.y);
    vec4 ph = phases(u_eye + tn * d);
    if (max(ph.r, ph.g) < u_iso || tn >= span.y) {
      left = true;
      break;
    }
    w = ph.r / (ph.r + ph.g);
    if (water_in_front < 0.0 && w > 0.5) water_in_front = path_water;
    path_ice += (tn - tb) * w;
    path_water += (tn - tb) * (1.0 - w);
    if (THAW_TINT == 1) path_dye += (tn - tb) * dye(u_eye + tn * d);
    tb = tn;
  }
  bool solid_behind = false;
  if (left) {
    float inside_to = tb;
    for (int k = 0; k < kBisections; ++k) {
      float m = 0.5 * (inside_to + tn);
      vec4 ph = phases(u_eye + m * d);
      if (max(ph.r, ph.g) < u_iso)
        tn = m;
      else
        inside_to = m;
    }
    path_ice += (tn - tb) * w;
    path_water += (tn - tb) * (1.0 - w);
    if (THAW_TINT == 1) path_dye += (tn - tb) * dye(u_eye + 0.5 * (tb + tn) * d);
    // Where a medium meets a solid both fields sit near iso at the exit: look a cell further.
    solid_behind = phases(u_eye + (tn + 1.0) * d).b >= u_iso;
    tb = tn;
  }

  // What lies behind, shaded opaque: the next surface along the ray, or the background.
  vec3 back = background(d);
  if (solid_behind) {
    // The union field is flat across a medium-solid interface; the solid's own field has the normal.
    vec3 q = u_eye + tb * d;
    const vec2 e = vec2(1.0, -1.0);
    vec3 g = e.xyy * phases(q + e.xyy).b + e.yyx * phases(q + e.yyx).b + e.yxy * phases(q + e.yxy).b +
             e.xxx * phases(q + e.xxx).b;
    back = lit(stained(kSolidColour, q, phases(q).b), q, length(g) > 1e-6 ? -normalize(g) : -d);
  } else if (THAW_SEE_BEHIND == 1 && left && tb + 1.0 < span.y) {
    // From a cell beyond the exit: at the exit itself the float field may still read above iso (the
    // exit was found on the 8-bit phases) and the medium would hit its own back face.
    float t2 = first_hit(u_eye, d, inv, tb + 1.0, span.y);
    if (t2 >= 0.0) {
      vec3 q = u_eye + t2 * d;
      int behind = dominant(phases(q));
      // Glass behind the medium (a glass's far wall): the background, tinted, through it.
      back = behind == 3 ? background(d) * kGlassColour
                         : lit(behind == 2 ? kSolidColour : behind == 0 ? kIceColour * 0.85 : kWaterColour * 1.4,
                               q, outward_normal(q, d));
    }
  }

  // Beer-Lambert along the path: absorption dims what lies behind; scattering replaces it with the
  // medium's own colour, lit with wrap-around diffuse since light diffuses inside it.
  float li = path_ice * u_scale, lw = path_water * u_scale;
  vec3 transmitted = back * exp(-(kIceAbsorption * li + kWaterAbsorption * lw));
  float scatter = phase == 0 ? max(1.0 - exp(-kIceScattering * li), kIceMinScatter)
                             : 1.0 - exp(-kWaterScattering * lw);
  float wrap = 0.5 + 0.5 * dot(n, u_light);
  vec3 light = 0.45 * ambient(n) * ao + 0.65 * wrap * sh;
  vec3 medium = (phase == 0 ? stained(kIceColour, p, phases(p).r) : kWaterColour) * light;
  vec3 body = mix(transmitted, medium, scatter);
  if (phase == 1 && water_in_front >= 0.0) {
    // Ice under water: the ice scatters as ice in front of what lies behind it, and the water in front
    // of the ice tints and veils that, so submerged ice reads as ice (in fast quality too).
    float lf = water_in_front * u_scale;
    vec3 ice_look = mix(back * exp(-(kIceAbsorption * li + kWaterAbsorption * (lw - lf))), kIceColour * light,
                        max(1.0 - exp(-kIceScattering * li), kIceMinScatter));
    body = mix(ice_look * exp(-kWaterAbsorption * lf), medium, 1.0 - exp(-kWaterScattering * lf));
  }

#if THAW_TINT
  // The dye filters what passes through the path by Beer-Lambert, and scatters its own colour as a cloud of it
  // would, opaque where thick: dilute dye is a tint over the water, a dense one the dye's colour.
  vec3 tau = u_dye_absorption * (path_dye * u_scale);
  float cloud = 1.0 - exp(-0.5 * max(max(tau.r, tau.g), tau.b));
  body = mix(body * exp(-tau), u_stain_colour * light, cloud);
#endif

  // Schlick's approximation of the Fresnel reflectance (Schlick 1994, "An inexpensive BRDF model for
  // physically-based rendering"), reflecting the background, plus a highlight of the key light.
  float fresnel = schlick(phase == 0 ? kIceF0 : kWaterF0, n, d);
  vec3 r = reflect(d, n);
  float shininess = phase == 0 ? 40.0 : 120.0;  // ice's surface is rougher than water's
  float highlight = (phase == 0 ? 0.35 : 0.8) * pow(max(dot(r, u_light), 0.0), shininess) * sh;
  return mix(body, background(r), fresnel) + highlight;
}

// The nearest t > 0 where the ray meets a capped cylinder from a to b of radius r, with the outward
// normal in n; -1 on a miss. The quadratic of the infinite cylinder, then the caps (the construction
// of Quilez's "intersectors" capped cylinder).
float cylinder_hit(vec3 ro, vec3 rd, vec3 a, vec3 b, float r, out vec3 n) {
  vec3 ba = b - a, oc = ro - a;
  float baba = dot(ba, ba), bard = dot(ba, rd), baoc = dot(ba, oc);
  float k2 = baba - bard * bard;
  float k1 = baba * dot(oc, rd) - baoc * bard;
  float k0 = baba * dot(oc, oc) - baoc * baoc - r * r * baba;
  float h = k1 * k1 - k2 * k0;
  n = vec3(0.0);
  if (h < 0.0 || abs(k2) < 1e-9) return -1.0;
  h = sqrt(h);
  float t = (-k1 - h) / k2;
  float y = baoc + t * bard;
  if (y > 0.0 && y < baba && t > 0.0) {
    n = (oc + t * rd - ba * y / baba) / r;
    return t;
  }
  t = ((y < 0.0 ? 0.0 : baba) - baoc) / bard;
  if (abs(k1 + k2 * t) < h && t > 0.0) {
    n = ba * sign(y) / sqrt(baba);
    return t;
  }
  return -1.0;
}

// The dryers over `colour`, for a ray whose first opaque surface lies at t_scene.
vec3 draw_dryers(vec3 colour, vec3 d, float t_scene) {
  float nearest = t_scene;
  for (int k = 0; k < 4; ++k) {
    if (k >= u_dryers) break;
    vec3 a = u_dryer_pos[k], dir = u_dryer_dir[k];
    vec4 shape = u_dryer_shape[k];
    float r = shape.x;
    // The warm cone while blowing: its length along the ray, sampled over the cone's bounding sphere.
    if (shape.w > 0.5) {
      // Drawn to the end of its reach or where its axis leaves the fields' box, whichever comes first:
      // the air goes no further than the floor.
      vec3 dir_safe = mix(dir, vec3(1e-6), lessThan(abs(dir), vec3(1e-6)));
      vec2 axis = clip_to_box(a, 1.0 / dir_safe);
      float reach = axis.x <= axis.y ? min(shape.z, axis.y) : shape.z;
      vec3 c = a + dir * (0.5 * reach);
      float R = length(vec2(0.5 * reach, reach * shape.y + r));
      vec3 oc = u_eye - c;
      float b = dot(oc, d), q = dot(oc, oc) - R * R, h = b * b - q;
      if (h > 0.0) {
        h = sqrt(h);
        float t0 = max(-b - h, 0.0), t1 = min(-b + h, nearest);
        float inside = 0.0;
        const int kSamples = 12;
        float dt = (t1 - t0) / float(kSamples);
        for (int i = 0; i < kSamples; ++i) {
          vec3 x = u_eye + (t0 + (float(i) + 0.5) * dt) * d - a;
          float along = dot(x, dir);
          float across = length(x - along * dir);
          inside += (along > 0.0 && along < reach && across < along * shape.y + r) ? dt : 0.0;
        }
        // A faint haze: at most a quarter of the way to warm orange.
        float density = 0.8 / max(reach * shape.y + r, 1.0);
        colour = mix(colour, vec3(1.0, 0.62, 0.3), 0.25 * (1.0 - exp(-density * max(inside, 0.0))));
      }
    }
    // The nozzle: a dark cylinder one and a half radii long behind the outlet.
    vec3 n;
    float t = cylinder_hit(u_eye, d, a - dir * (1.5 * r), a, r, n);
    if (t > 0.0 && t < nearest) {
      nearest = t;
      float lambert = max(dot(n, u_light), 0.0);
      colour = vec3(0.16, 0.17, 0.19) * (0.5 * ambient(n) + 0.8 * lambert) +
               0.4 * pow(max(dot(reflect(d, n), u_light), 0.0), 30.0);
    }
  }
  // Lamps: the rectangle centre +- u +- v, nearer than anything drawn so far.
  for (int k = 0; k < 4; ++k) {
    if (k >= u_lamps) break;
    vec3 c = u_lamp_centre[k], hu = u_lamp_u[k], hv = u_lamp_v[k];
    vec3 n = normalize(cross(hu, hv));
    float facing = dot(d, n);
    if (abs(facing) < 1e-6) continue;
    float t = dot(c - u_eye, n) / facing;
    if (t <= 0.0 || t >= nearest) continue;
    vec3 q = u_eye + t * d - c;
    if (abs(dot(q, hu)) > dot(hu, hu) || abs(dot(q, hv)) > dot(hv, hv)) continue;
    nearest = t;
    // cross(u, v) is the lamp's normal, out of its emitting side (sim/heat_stage.cpp lays u, v out so):
    // a ray against it sees the glowing face.
    bool front = facing < 0.0;
    colour = front && length(u_lamp_glow[k]) > 0.0 ? u_lamp_glow[k] : vec3(0.14, 0.14, 0.15);
  }
  return colour;
}

void main() {
  vec2 ndc = 2.0 * gl_FragCoord.xy / u_viewport - 1.0;
  vec3 d = normalize(u_forward + ndc.x * u_right + ndc.y * u_up);
  if (u_has_volume == 0) {
#if THAW_SOURCES
    o_colour = vec4(clamp(draw_dryers(background(d), d, 1e30), 0.0, 1.0), 1.0);
#else
    o_colour = vec4(background(d), 1.0);
#endif
    return;
  }
  // Keep 1/d finite: an axis-parallel ray would give 0 * inf = NaN at the box faces.
  d = mix(d, mix(vec3(1e-6), vec3(-1e-6), lessThan(d, vec3(0.0))), lessThan(abs(d), vec3(1e-6)));
  vec3 inv = 1.0 / d;
  vec2 span = clip_to_box(u_eye, inv);

  // Glass passes part of the light on: `through` is how much of what lies further along reaches the eye.
  vec3 colour = vec3(0.0), through = vec3(1.0);
  float from = span.x, t_scene = 1e30;  // t_scene: the first opaque surface, which hides the dryers
  bool ended = false;
#if THAW_GLASS
  const int kLayers = kGlassLayers;
#else
  const int kLayers = 1;
#endif
  for (int layer = 0; layer < kLayers; ++layer) {
    float t = span.x > span.y || from >= span.y ? -1.0 : first_hit(u_eye, d, inv, from, span.y);
    if (t < 0.0) {
      colour += through * background(d);
      ended = true;
      break;
    }
    vec3 p = u_eye + t * d;
    int phase = dominant(phases(p));
    vec3 n = normal_at(p, d, inv, span, t);
#if THAW_GLASS
    if (phase != 3) {
#endif
      t_scene = t;
      colour += through * shade(p, n, d, inv, span, t, phase);
      ended = true;
      break;
#if THAW_GLASS
    }
    // Glass: the reflection and a faint haze here; the rest goes on through the wall, to its far face.
    float f = schlick(kGlassF0, n, d);
    vec3 r = reflect(d, n);
    float sh = shadow(p, n);
    float highlight = 0.6 * pow(max(dot(r, u_light), 0.0), 200.0) * sh;
    vec3 haze = kGlassColour * (0.45 * ambient(n) + 0.4 * max(dot(n, u_light), 0.0) * sh);
    colour += through * (f * background(r) + kGlassHaze * haze + highlight);
    float te = t;
    for (int i = 0; i < kMaxGlass; ++i) {
      te = min(te + 1.0, span.y);
      if (te >= span.y || phases(u_eye + te * d).a < u_iso) break;
    }
    through *= (1.0 - f - kGlassHaze) * exp(-kGlassAbsorption * ((te - t) * u_scale));
    from = te + 0.5;  // past where the 8-bit glass field still reads near iso
#endif
  }
  if (!ended) colour += through * background(d);
#if THAW_SOURCES
  colour = draw_dryers(colour, d, t_scene);
#endif
  o_colour = vec4(clamp(colour, 0.0, 1.0), 1.0);
}
