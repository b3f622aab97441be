namespace capsflow {}
