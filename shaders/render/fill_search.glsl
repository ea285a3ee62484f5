// The hole filling's search (fill.comp over the picture, fill_again.comp over the first filling's
// output), for the pixel at index `i` (`padded` in the log-distance buffers) whose log distance is
// `here`: along each of the 8 directions, the first pixel within kFillRadius (a specialization
// constant of the shader) that stands in front of it by more than pc.fill_threshold, from the far
// end, so that the nearest hit wins (counting up: Mesa 22's NIR unrolls no loop that counts down).
// Where nothing is drawn a pixel is kEmpty (kEmpty less the threshold rounds to kEmpty: any drawn
// pixel stands in front), and the margin is never a hit. Then the axes with a hit both ways
// (`pairs`), the directions with one (`sides`), and the mean log distance and colour of the hits
// on the nearest surface found (`log_sum`, `color_sum` over `covered`: a pixel with nothing drawn
// may see the front surface one way and a back one another). llvmpipe runs every branch of every
// lane, so every step is paid for every pixel: no early exits, one colour load a direction.
// A macro, as LOGS and COLORS are the shader's own image bindings.
const ivec2 kDirections[8] = ivec2[8](ivec2(1, 0), ivec2(1, 1), ivec2(0, 1), ivec2(-1, 1), ivec2(-1, 0),
                                      ivec2(-1, -1), ivec2(0, -1), ivec2(1, -1));

#define FILL_SEARCH(LOGS, COLORS)                                                                             \
  float limit = here - pc.fill_threshold;                                                                     \
  float seen_log[8];                                                                                          \
  int seen_index[8];                                                                                          \
  float nearest = kEmpty;                                                                                     \
  [[unroll]] for (int k = 0; k < 8; ++k) {                                                                    \
    seen_log[k] = kEmpty;                                                                                     \
    seen_index[k] = i;                                                                                        \
    [[unroll]] for (int u = 0; u < kFillRadius; ++u) {                                                        \
      int t = kFillRadius - u;                                                                                \
      float l = imageLoad(LOGS, padded + t * paddedStep(kDirections[k])).r;                                   \
      bool hit = l < limit;                                                                                   \
      seen_log[k] = hit ? l : seen_log[k];                                                                    \
      seen_index[k] = hit ? i + t * (kDirections[k].y * int(pc.width) + kDirections[k].x) : seen_index[k];    \
    }                                                                                                         \
    nearest = min(nearest, seen_log[k]);                                                                      \
  }                                                                                                           \
  int pairs = 0, sides = 0;                                                                                   \
  [[unroll]] for (int k = 0; k < 4; ++k) pairs += (seen_log[k] < kEmpty && seen_log[k + 4] < kEmpty) ? 1 : 0; \
  [[unroll]] for (int k = 0; k < 8; ++k) sides += seen_log[k] < kEmpty ? 1 : 0;                               \
  vec3 color_sum = vec3(0.0);                                                                                 \
  float log_sum = 0.0;                                                                                        \
  int covered = 0;                                                                                            \
  [[unroll]] for (int k = 0; k < 8; ++k) {                                                                    \
    vec3 color = unpackUnorm4x8(imageLoad(COLORS, seen_index[k]).r).rgb;                                      \
    bool near = seen_log[k] <= nearest + pc.fill_threshold;                                                   \
    color_sum += near ? color : vec3(0.0);                                                                    \
    log_sum += near ? seen_log[k] : 0.0;                                                                      \
    covered += near ? 1 : 0;                                                                                  \
  }
