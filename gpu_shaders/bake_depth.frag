/* Depth pre-pass: only the depth attachment matters. */
void main()
{
  dummy_out = 0.0;
}
