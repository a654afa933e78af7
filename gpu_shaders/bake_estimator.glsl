/* The bake's estimator (hao_addon/core/bake/estimators.py, the numpy twin and the defines):
 * what one direction adds to a receiver's sums, ESTIMATOR_CHANNELS floats with the weight sum
 * last, and how the sums are kept in the accumulator image (RG32F for 2 channels, RGBA32F
 * for 4). weight: the hemisphere weight times 1 / S; visible: in [0, 1]; omega: towards the
 * light. */
#if defined(ESTIMATOR_AMBIENT_OCCLUSION)
/* (w V, w): accessibility = sum(w V) / sum(w). */
#  define ESTIMATOR_TERM(weight, visible, omega) vec2((weight) * (visible), (weight))
#endif

#if ESTIMATOR_CHANNELS == 2
#  define EstimatorSums vec2
#  define ESTIMATOR_LOAD(image, slot) imageLoad(image, slot).xy
#  define ESTIMATOR_STORE(image, slot, sums) imageStore(image, slot, vec4(sums, 0.0, 0.0))
#elif ESTIMATOR_CHANNELS == 4
#  define EstimatorSums vec4
#  define ESTIMATOR_LOAD(image, slot) imageLoad(image, slot)
#  define ESTIMATOR_STORE(image, slot, sums) imageStore(image, slot, sums)
#endif
