/* The bake's estimator (hao_addon/core/bake/estimators.py, the numpy twin and the defines):
 * what one direction adds to a receiver's sums, ESTIMATOR_CHANNELS floats with the weight sum
 * last, and how the sums are kept in the accumulator image (RG32F for 2 channels, RGBA32F
 * for 4, two RGBA32F images for 8). weight: the hemisphere weight times 1 / S; visible: in [0, 1]; omega: towards the
 * light. */
#if defined(ESTIMATOR_AMBIENT_OCCLUSION)
/* (w V, w): accessibility = sum(w V) / sum(w). */
#  define ESTIMATOR_TERM(weight, visible, omega) vec2((weight) * (visible), (weight))
#elif defined(ESTIMATOR_BENT_NORMALS)
/* (w V, w V omega) and (w omega, w): accessibility and the bent normal (the mean unoccluded
 * direction; the mean open direction where nothing is visible). */
#  define ESTIMATOR_TERM(weight, visible, omega) \
    mat2x4(vec4((weight) * (visible), ((weight) * (visible)) * (omega)), vec4((weight) * (omega), (weight)))
#endif

#if ESTIMATOR_CHANNELS == 2
#  define EstimatorSums vec2
#  define ESTIMATOR_LOAD(image, slot) imageLoad(image, slot).xy
#  define ESTIMATOR_STORE(image, slot, sums) imageStore(image, slot, vec4(sums, 0.0, 0.0))
#elif ESTIMATOR_CHANNELS == 4
#  define EstimatorSums vec4
#  define ESTIMATOR_LOAD(image, slot) imageLoad(image, slot)
#  define ESTIMATOR_STORE(image, slot, sums) imageStore(image, slot, sums)
#elif ESTIMATOR_CHANNELS == 8
/* Two RGBA32F images: `image` holds the first four channels, accum_high the last four. */
#  define EstimatorSums mat2x4
#  define ESTIMATOR_LOAD(image, slot) mat2x4(imageLoad(image, slot), imageLoad(accum_high, slot))
#  define ESTIMATOR_STORE(image, slot, sums) \
    imageStore(image, slot, (sums)[0]); \
    imageStore(accum_high, slot, (sums)[1])
#endif
