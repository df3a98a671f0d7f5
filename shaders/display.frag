#version 330 core
// Shows the session's mean radiance exactly as the PNG writer maps it
// (renderer/film/image_io.cpp: tone_map_channel), so what is on screen is what
// a screenshot saves.
in vec2 uv;
out vec4 color;

uniform sampler2D mean_radiance;  // linear float RGB
uniform float exposure;           // linear factor, 2^EV
uniform int transfer;             // 0: the book's gamma 2 (sqrt), 1: sRGB

vec3 encode(vec3 x) {
    if (transfer == 0) return sqrt(x);
    vec3 lo = 12.92 * x;
    vec3 hi = 1.055 * pow(x, vec3(1.0 / 2.4)) - 0.055;
    return mix(hi, lo, vec3(lessThanEqual(x, vec3(0.0031308))));
}

void main() {
    vec3 x = texture(mean_radiance, uv).rgb * exposure;
    // NaN and negatives map to black, as in the file writer.
    x = vec3(x.r > 0.0 ? x.r : 0.0, x.g > 0.0 ? x.g : 0.0, x.b > 0.0 ? x.b : 0.0);
    // The book's quantiser: 256 * clamp(v, 0, 0.999), truncated.
    vec3 level = floor(256.0 * clamp(encode(x), 0.0, 0.999));
    color = vec4(level / 255.0, 1.0);
}
