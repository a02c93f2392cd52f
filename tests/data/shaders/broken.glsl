// Included by include_error.frag: the error is on line 3 of this file.
float broken_helper(float x)
{ return x * undefined_thing; }
