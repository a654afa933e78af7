/* Depth pre-pass: only the depth attachment matters. */
void main()
{
#ifdef ALPHA
  if (!alpha_keeps()) {
    discard;
  }
#endif
  dummy_out = 0.0;
}
