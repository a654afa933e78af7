/* Distant-occluder billboards (Shanmugam & Arikan, section 5.2): one screen rectangle per
 * sphere, computed on the CPU to conservatively cover the projection of the ball of radius
 * d_far around the sphere (hao_addon/gpu/sphere_far.py). */
void main()
{
  sphere_data = sphere;
  sphere_reach = reach;
  gl_Position = vec4(corner, 0.0, 1.0);
}
